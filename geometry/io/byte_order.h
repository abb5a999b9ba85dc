#pragma once
// Loads and stores with an explicit byte order for the binary formats (COLMAP .bin,
// PFM), so that reading and writing do not depend on the host's byte order.
#include <bit>
#include <cstddef>
#include <cstdint>
#include <string>

namespace saresgs::byte_order {

template <std::size_t N>
struct UnsignedOfSize;
template <>
struct UnsignedOfSize<1> {
  using type = std::uint8_t;
};
template <>
struct UnsignedOfSize<2> {
  using type = std::uint16_t;
};
template <>
struct UnsignedOfSize<4> {
  using type = std::uint32_t;
};
template <>
struct UnsignedOfSize<8> {
  using type = std::uint64_t;
};

// The T stored in `order` in the sizeof(T) bytes at `p`.
template <typename T>
T load(const char* p, std::endian order) {
  using U = typename UnsignedOfSize<sizeof(T)>::type;
  U u = 0;
  for (std::size_t i = 0; i < sizeof(T); ++i) {
    const std::size_t byte = order == std::endian::little ? i : sizeof(T) - 1 - i;
    u = static_cast<U>(u | static_cast<U>(static_cast<U>(static_cast<unsigned char>(p[i])) << (8 * byte)));
  }
  return std::bit_cast<T>(u);
}

template <typename T>
void appendLittleEndian(std::string& out, T value) {
  using U = typename UnsignedOfSize<sizeof(T)>::type;
  const U u = std::bit_cast<U>(value);
  for (std::size_t i = 0; i < sizeof(T); ++i) out.push_back(static_cast<char>((u >> (8 * i)) & 0xffu));
}

}  // namespace saresgs::byte_order
