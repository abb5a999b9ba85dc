#include "geometry/occupancy/vdb_mask.h"

#include <dlfcn.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <stdexcept>
#include <utility>

#include "geometry/occupancy/vdb_backend.h"

#ifndef SARESGS_VDB_MODULE_PATH
#define SARESGS_VDB_MODULE_PATH ""
#endif

namespace saresgs {

namespace {

constexpr const char* kModuleName = "libsaresgs_vdb.so";

struct Loaded {
  const vdb_module::Backend* ops = nullptr;
  std::string path;
};

// The module's candidates, in order: $SARESGS_VDB_MODULE alone when it is set; else the
// folder of the binary that holds this code (the program, a test or the Python module,
// so a copy moved together with the module finds it), then the build's own path.
std::vector<std::string> candidates() {
  if (const char* env = std::getenv("SARESGS_VDB_MODULE"); env && *env) return {env};
  std::vector<std::string> out;
  Dl_info info{};
  if (dladdr(reinterpret_cast<void*>(&candidates), &info) && info.dli_fname && *info.dli_fname) {
    std::error_code ec;
    const auto self = std::filesystem::canonical(info.dli_fname, ec);
    if (!ec) out.push_back((self.parent_path() / kModuleName).string());
  }
  const std::string built = SARESGS_VDB_MODULE_PATH;
  if (!built.empty() && std::find(out.begin(), out.end(), built) == out.end()) out.push_back(built);
  return out;
}

Loaded load() {
  std::string tried;
  for (const std::string& path : candidates()) {
    void* handle = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!handle) {
      const char* err = dlerror();
      tried += "\n  " + path + ": " + (err ? err : "not loaded");
      continue;
    }
    using Entry = const vdb_module::Backend* (*)();
    auto entry = reinterpret_cast<Entry>(dlsym(handle, "saresgs_vdb_backend"));
    const vdb_module::Backend* ops = entry ? entry() : nullptr;
    if (!ops || ops->abi != vdb_module::kAbi) {
      tried += "\n  " + path + ": not this build's OpenVDB module (entry point or ABI " +
               std::to_string(vdb_module::kAbi) + " missing)";
      dlclose(handle);
      continue;
    }
    return {ops, path};  // kept loaded for the life of the process
  }
  throw std::runtime_error("OpenVDB module: cannot load " + std::string(kModuleName) + "; tried:" + tried +
                           "\n  (build the saresgs_vdb target, or set SARESGS_VDB_MODULE to the module's path)");
}

// Loaded once per process, on first use (a failure is thrown to every caller).
const Loaded& loaded() {
  static const Loaded l = load();
  return l;
}

}  // namespace

std::string vdbModulePath() { return loaded().path; }

VdbMask::VdbMask() : ops_(loaded().ops), tree_(ops_->create()) {}
VdbMask::VdbMask(const VdbMask& o) : ops_(o.ops_), tree_(o.tree_ ? ops_->copy(o.tree_) : ops_->create()) {}
VdbMask& VdbMask::operator=(const VdbMask& o) {
  if (this != &o) {
    VdbMask c(o);
    std::swap(tree_, c.tree_);
  }
  return *this;
}
// A moved-from mask holds no tree: it may only be destroyed or assigned to.
VdbMask::VdbMask(VdbMask&& o) noexcept : ops_(o.ops_), tree_(std::exchange(o.tree_, nullptr)) {}
VdbMask& VdbMask::operator=(VdbMask&& o) noexcept {
  std::swap(tree_, o.tree_);
  return *this;
}
VdbMask::~VdbMask() {
  if (tree_) ops_->destroy(tree_);
}

void VdbMask::setOn(std::span<const Voxel> voxels) { ops_->setOn(tree_, voxels.data(), voxels.size()); }
bool VdbMask::isOn(const Voxel& v) const { return ops_->isOn(tree_, v); }

VoxelSet VdbMask::filter(const VoxelSet& set) const {
  std::vector<VoxelKey> out;
  ops_->filterKeys(tree_, set.keys().data(), set.size(), out);
  return VoxelSet::fromSortedKeys(std::move(out));  // a subsequence of sorted keys
}

void VdbMask::dilate(int radius, DilationShape shape) { ops_->dilate(tree_, radius, shape); }
void VdbMask::unite(const VdbMask& o) { ops_->unite(tree_, o.tree_); }
void VdbMask::clear() { ops_->clear(tree_); }
bool VdbMask::empty() const { return ops_->empty(tree_); }
std::size_t VdbMask::activeCount() const { return ops_->activeCount(tree_); }

VoxelSet VdbMask::keys() const {
  std::vector<VoxelKey> keys;
  ops_->activeKeys(tree_, keys);
  // Tree iteration order (by child index inside each internal node) is not key order.
  std::sort(keys.begin(), keys.end());
  return VoxelSet::fromSortedKeys(std::move(keys));
}

bool VdbMask::bounds(Voxel& lo, Voxel& hi) const { return ops_->bounds(tree_, lo, hi); }
std::size_t VdbMask::memUsage() const { return ops_->memUsage(tree_); }

}  // namespace saresgs
