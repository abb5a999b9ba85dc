#pragma once
// The floating-point environment our numeric code runs in: IEEE 754 as compiled (denormals
// kept, not flushed; round to nearest). Embree's BVH builds set the x86 flush-to-zero and
// denormals-are-zero modes on the TBB worker threads that run them and leave them set (its
// documentation recommends both for ray tracing speed), so without a guard a parallel loop
// of ours that later runs on such a thread rounds tiny values (an Adam moment of a
// rotation gradient of 1e-20, say) otherwise than on the main thread. The result then
// depended on which thread ran which block and on whether Embree had run in the process
// before (a Python session that made a scene, then trained; an ablation shard running a
// hybrid job, then a random one). Every TBB task body of ours opens with a FloatEnvGuard,
// which sets the environment for the task and restores the thread's own afterwards.
#if defined(__SSE__) || defined(__x86_64__)
#include <xmmintrin.h>
#endif

namespace saresgs {

class FloatEnvGuard {
 public:
#if defined(__SSE__) || defined(__x86_64__)
  // MXCSR: FTZ (bit 15), DAZ (bit 6) and the rounding control (bits 13-14) cleared; the
  // exception masks and status flags kept.
  static constexpr unsigned kModeBits = 0x8000u | 0x0040u | 0x6000u;
  FloatEnvGuard() : saved_(_mm_getcsr()) {
    if (saved_ & kModeBits) _mm_setcsr(saved_ & ~kModeBits);
  }
  ~FloatEnvGuard() {
    if (saved_ & kModeBits) _mm_setcsr(saved_);
  }

 private:
  unsigned saved_;
#endif
 public:
  FloatEnvGuard(const FloatEnvGuard&) = delete;
  FloatEnvGuard& operator=(const FloatEnvGuard&) = delete;
};

}  // namespace saresgs
