// Tile binning and depth order (rule 6 of splat/rasterize.h): every tile's list of
// (tile, Gaussian) pairs, front to back.
#include "splat/raster/raster_stages.h"
#include <tbb/parallel_invoke.h>

#include <type_traits>
#include <utility>

namespace saresgs::raster_stage {
namespace {

// The scratch of binAndSort and depthOrder, kept per thread between renders
// (splat/kept_buffers.h).
struct BinScratch {
  std::vector<std::uint32_t> slot_tile, order, key, key2, order2, chunk_fill;
};

// Rule 6 for every tile at once: the Gaussians with pairs, by camera z, ties by index.
// Binning them in this order (a stable counting sort by tile) leaves every tile sorted,
// which costs far less than sorting each tile. Float depths go through a stable LSD radix
// sort on their bits (mapped so that unsigned order is float order); double uses
// std::sort. The order goes to `sc.order`.
template <typename T>
void depthOrder(const std::vector<Projected<T>>& proj, const std::vector<std::uint32_t>& count, BinScratch& sc) {
  std::vector<std::uint32_t>& order = sc.order;
  order.clear();
  order.reserve(proj.size());
  for (std::size_t i = 0; i < proj.size(); ++i)
    if (count[i]) order.push_back(static_cast<std::uint32_t>(i));
  if constexpr (std::is_same_v<T, float>) {
    const std::size_t m = order.size();
    std::vector<std::uint32_t>& key = sc.key;
    std::vector<std::uint32_t>& key2 = sc.key2;
    std::vector<std::uint32_t>& order2 = sc.order2;
    key.resize(m);
    key2.resize(m);
    order2.resize(m);
    for (std::size_t j = 0; j < m; ++j) {
      // + 0 turns -0 into +0, which the comparison of rule 6 treats as equal.
      const std::uint32_t b = std::bit_cast<std::uint32_t>(proj[order[j]].depth + 0.0f);
      key[j] = (b & 0x80000000u) ? ~b : (b | 0x80000000u);
    }
    constexpr int kBits = 11, kBuckets = 1 << kBits;
    for (int shift = 0; shift < 32; shift += kBits) {
      std::array<std::uint32_t, kBuckets + 1> start{};
      for (std::size_t j = 0; j < m; ++j) ++start[((key[j] >> shift) & (kBuckets - 1)) + 1];
      for (int k = 0; k < kBuckets; ++k) start[k + 1] += start[k];
      for (std::size_t j = 0; j < m; ++j) {
        const std::uint32_t d = start[(key[j] >> shift) & (kBuckets - 1)]++;
        key2[d] = key[j];
        order2[d] = order[j];
      }
      key.swap(key2);
      order.swap(order2);
    }
  } else {
    std::sort(order.begin(), order.end(), [&](std::uint32_t x, std::uint32_t y) {
      return proj[x].depth < proj[y].depth || (proj[x].depth == proj[y].depth && x < y);
    });
  }
}

}  // namespace

template <typename T>
void binAndSort(const TileCover& cover, int W, int H, RasterStateT<T>& st) {
  const std::size_t n = cover.count.size();
  const int tiles = st.tiles_x * st.tiles_y;
  st.gauss_start.assign(n + 1, 0);
  for (std::size_t i = 0; i < n; ++i) st.gauss_start[i + 1] = st.gauss_start[i] + cover.count[i];
  const std::uint32_t pairs = st.gauss_start[n];
  KeptBuffers<BinScratch> kept;
  BinScratch& sc = kept.get();
  std::vector<std::uint32_t>& slot_tile = sc.slot_tile;
  assignKept(slot_tile, pairs, 0u);
  arena(st).execute([&] {
    // The pairs' tiles and the depth order (serial) do not depend on each other.
    tbb::parallel_invoke(
        [&] {
          const FloatEnvGuard fenv;  // geometry/float_env.h (depths are floats)
          depthOrder(st.proj, cover.count, sc);
        },
        [&] {
          tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 1024), [&](const auto& r) {
            const FloatEnvGuard fenv;  // geometry/float_env.h
            for (std::size_t i = r.begin(); i < r.end(); ++i) {
              if (!cover.count[i]) continue;
              std::uint32_t k = st.gauss_start[i];
              forEachCoveredTile(cover, i, st.tile_data[i], W, H, [&](int tx, int ty) {
                slot_tile[k++] = static_cast<std::uint32_t>(ty * st.tiles_x + tx);
              });
            }
          });
        });
  });
  // A stable counting sort of the pairs by tile, the Gaussians taken in depth order, in
  // parallel: the depth order is cut into chunks, each chunk counts its pairs per tile,
  // and each chunk's pairs go to its tile after those of the chunks before it, which is
  // where the serial loop put them (the same lists for any number of chunks or threads).
  const std::vector<std::uint32_t>& order = sc.order;
  const std::size_t m = order.size();
  const std::size_t chunks = std::clamp<std::size_t>(m / 2048, 1, 16);
  auto chunkRange = [&](std::size_t c) { return std::pair{c * m / chunks, (c + 1) * m / chunks}; };
  const std::size_t nt = static_cast<std::size_t>(tiles);
  std::vector<std::uint32_t>& cf = sc.chunk_fill;
  assignKept(cf, chunks * nt, 0u);
  auto forChunks = [&](auto&& body) {
    arena(st).execute([&] {
      tbb::parallel_for(std::size_t{0}, chunks, [&](std::size_t c) {
        const FloatEnvGuard fenv;  // geometry/float_env.h (integers only, but every task body has one)
        const auto [b, e] = chunkRange(c);
        body(c, b, e);
      });
    });
  };
  forChunks([&](std::size_t c, std::size_t b, std::size_t e) {
    std::uint32_t* cnt = cf.data() + c * nt;
    for (std::size_t j = b; j < e; ++j) {
      const std::uint32_t i = order[j];
      for (std::uint32_t k = st.gauss_start[i]; k < st.gauss_start[i + 1]; ++k) ++cnt[slot_tile[k]];
    }
  });
  // Counts to starts: the tile's start, then each chunk's place within the tile.
  st.tile_start.assign(nt + 1, 0);
  std::uint32_t at = 0;
  for (std::size_t t = 0; t < nt; ++t) {
    st.tile_start[t] = at;
    for (std::size_t c = 0; c < chunks; ++c) {
      const std::uint32_t k = cf[c * nt + t];
      cf[c * nt + t] = at;
      at += k;
    }
  }
  st.tile_start[nt] = at;
  st.entry_gauss.resize(pairs);
  st.pair_entry.resize(pairs);
  forChunks([&](std::size_t c, std::size_t b, std::size_t e) {
    std::uint32_t* fill = cf.data() + c * nt;
    for (std::size_t j = b; j < e; ++j) {
      const std::uint32_t i = order[j];
      for (std::uint32_t k = st.gauss_start[i]; k < st.gauss_start[i + 1]; ++k) {
        const std::uint32_t en = fill[slot_tile[k]]++;
        st.entry_gauss[en] = i;
        st.pair_entry[k] = en;
      }
    }
  });
}

template void binAndSort(const TileCover&, int, int, RasterStateT<float>&);
template void binAndSort(const TileCover&, int, int, RasterStateT<double>&);

}  // namespace saresgs::raster_stage
