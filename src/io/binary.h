#pragma once
// Numbers stored as bytes in VTK files, whatever the byte order of this machine.

#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <type_traits>

namespace vrd::io {

enum class Scalar { Int8, UInt8, Int16, UInt16, Int32, UInt32, Int64, UInt64, Float32, Float64 };

/// Type names as VTK XML writes them ("Float32", "UInt8", ...); nullopt for anything else.
std::optional<Scalar> scalarFromXmlName(std::string_view name);
/// Type names of VTK legacy files ("float", "vtktypeint64", ...); nullopt for anything else.
std::optional<Scalar> scalarFromLegacyName(std::string_view name);

constexpr std::size_t sizeOf(Scalar s) {
  switch (s) {
    case Scalar::Int8:
    case Scalar::UInt8:
      return 1;
    case Scalar::Int16:
    case Scalar::UInt16:
      return 2;
    case Scalar::Int32:
    case Scalar::UInt32:
    case Scalar::Float32:
      return 4;
    default:
      return 8;
  }
}
constexpr bool isFloat(Scalar s) { return s == Scalar::Float32 || s == Scalar::Float64; }

/// The unsigned integer of `bytes` (1 to 8) bytes at `p`.
inline std::uint64_t loadUnsigned(const unsigned char* p, std::size_t bytes, bool bigEndian) {
  std::uint64_t value = 0;
  for (std::size_t k = 0; k < bytes; ++k) {
    const std::size_t shift = 8 * (bigEndian ? bytes - 1 - k : k);
    value |= static_cast<std::uint64_t>(p[k]) << shift;
  }
  return value;
}

/// The value of type `s` at `p` as T (double or std::int64_t). An unsigned 64-bit value above the
/// int64 range saturates; a float read as an integer is truncated (callers reject float index arrays).
template <typename T>
T loadScalar(const unsigned char* p, Scalar s, bool bigEndian) {
  const std::uint64_t u = loadUnsigned(p, sizeOf(s), bigEndian);
  switch (s) {
    case Scalar::Int8:
      return static_cast<T>(static_cast<std::int8_t>(u));
    case Scalar::UInt8:
      return static_cast<T>(static_cast<std::uint8_t>(u));
    case Scalar::Int16:
      return static_cast<T>(static_cast<std::int16_t>(u));
    case Scalar::UInt16:
      return static_cast<T>(static_cast<std::uint16_t>(u));
    case Scalar::Int32:
      return static_cast<T>(static_cast<std::int32_t>(u));
    case Scalar::UInt32:
      return static_cast<T>(static_cast<std::uint32_t>(u));
    case Scalar::Int64:
      return static_cast<T>(static_cast<std::int64_t>(u));
    case Scalar::UInt64:
      return u > static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max())
                 ? static_cast<T>(std::numeric_limits<std::int64_t>::max())
                 : static_cast<T>(u);
    case Scalar::Float32: {
      const float f = std::bit_cast<float>(static_cast<std::uint32_t>(u));
      if constexpr (std::is_floating_point_v<T>) return static_cast<T>(f);
      return std::isfinite(f) && std::abs(f) < 9e18f ? static_cast<T>(f) : T(-1);
    }
    case Scalar::Float64: {
      const double d = std::bit_cast<double>(u);
      if constexpr (std::is_floating_point_v<T>) return static_cast<T>(d);
      return std::isfinite(d) && std::abs(d) < 9e18 ? static_cast<T>(d) : T(-1);
    }
  }
  return T(0);
}

/// Appends `value` to `out` little-endian.
template <typename U>
void storeLittle(std::string& out, U value) {
  using Bits = std::conditional_t<sizeof(U) == 1, std::uint8_t,
                                  std::conditional_t<sizeof(U) == 4, std::uint32_t, std::uint64_t>>;
  const auto bits = std::bit_cast<Bits>(value);
  for (std::size_t k = 0; k < sizeof(U); ++k)
    out += static_cast<char>((static_cast<std::uint64_t>(bits) >> (8 * k)) & 0xff);
}

}  // namespace vrd::io
