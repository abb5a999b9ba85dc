#pragma once
// Buffers a function keeps per thread between calls, so that a call made every training
// iteration allocates nothing once they have grown. A thread that waits in TBB runs other
// tasks meanwhile, which may call the same function again (a call nested in the wait):
// that call gets buffers of its own, so no two calls share them at once.
namespace saresgs {

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
