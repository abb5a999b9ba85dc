#pragma once
// Buffers a function keeps per thread between calls, so that a call made every training
// iteration allocates nothing once they have grown. A thread that waits in TBB runs other
// tasks meanwhile, which may call the same function again (a call nested in the wait):
// that call gets buffers of its own, so no two calls share them at once.
#include <cstddef>

namespace saresgs {

// Room for n in a kept buffer: when it must grow it takes half as much again (its old
// contents dropped), so a size that creeps up from call to call (the tile pairs of a
// model in training) does not reallocate at every call, as assign's exact growth, or
// resize's after a shrink, would.
template <class Vec>
void reserveKept(Vec& v, std::size_t n) {
  if (n > v.capacity()) {
    v.clear();
    v.reserve(n + n / 2);
  }
}

// v.assign(n, x) for a kept buffer (reserveKept's growth).
template <class Vec, class X>
void assignKept(Vec& v, std::size_t n, const X& x) {
  reserveKept(v, n);
  v.assign(n, x);
}

template <class Buffers>
class KeptBuffers {
 public:
  KeptBuffers() : slot_(slot()), nested_(slot_.busy) { slot_.busy = true; }
  ~KeptBuffers() {
    if (!nested_) slot_.busy = false;
  }
  KeptBuffers(const KeptBuffers&) = delete;
  KeptBuffers& operator=(const KeptBuffers&) = delete;
  Buffers& get() { return nested_ ? fresh_ : slot_.buffers; }

 private:
  struct Slot {
    Buffers buffers;
    bool busy = false;
  };
  static Slot& slot() {
    thread_local Slot s;
    return s;
  }
  Slot& slot_;
  bool nested_;
  Buffers fresh_;
};

}  // namespace saresgs
