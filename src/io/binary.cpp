#include "io/binary.h"

#include <utility>

namespace vrd::io {

std::optional<Scalar> scalarFromXmlName(std::string_view name) {
  static constexpr std::pair<std::string_view, Scalar> kNames[] = {
      {"Int8", Scalar::Int8},       {"UInt8", Scalar::UInt8},     {"Int16", Scalar::Int16}, {"UInt16", Scalar::UInt16},
      {"Int32", Scalar::Int32},     {"UInt32", Scalar::UInt32},   {"Int64", Scalar::Int64}, {"UInt64", Scalar::UInt64},
      {"Float32", Scalar::Float32}, {"Float64", Scalar::Float64},
  };
  for (const auto& [n, s] : kNames)
    if (n == name) return s;
  return std::nullopt;
}

std::optional<Scalar> scalarFromLegacyName(std::string_view name) {
  // "long" is 8 bytes: what VTK writes on the 64-bit Unix systems this library targets.
  static constexpr std::pair<std::string_view, Scalar> kNames[] = {
      {"char", Scalar::Int8},          {"unsigned_char", Scalar::UInt8},
      {"short", Scalar::Int16},        {"unsigned_short", Scalar::UInt16},
      {"int", Scalar::Int32},          {"unsigned_int", Scalar::UInt32},
      {"long", Scalar::Int64},         {"unsigned_long", Scalar::UInt64},
      {"vtktypeint8", Scalar::Int8},   {"vtktypeuint8", Scalar::UInt8},
      {"vtktypeint16", Scalar::Int16}, {"vtktypeuint16", Scalar::UInt16},
      {"vtktypeint32", Scalar::Int32}, {"vtktypeuint32", Scalar::UInt32},
      {"vtktypeint64", Scalar::Int64}, {"vtktypeuint64", Scalar::UInt64},
      {"float", Scalar::Float32},      {"double", Scalar::Float64},
  };
  for (const auto& [n, s] : kNames)
    if (n == name) return s;
  return std::nullopt;
}

}  // namespace vrd::io
