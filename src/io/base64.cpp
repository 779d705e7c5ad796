#include "io/base64.h"

#include <fmt/format.h>

#include <array>
#include <limits>

#include "vrdeform/core/text_tokens.h"

namespace vrd::io {
namespace {

constexpr char kAlphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

constexpr std::array<signed char, 256> makeValues() {
  std::array<signed char, 256> values{};
  for (auto& v : values) v = -1;
  for (int i = 0; i < 64; ++i) values[static_cast<unsigned char>(kAlphabet[i])] = static_cast<signed char>(i);
  return values;
}
constexpr std::array<signed char, 256> kValues = makeValues();

}  // namespace

void base64Encode(std::string_view bytes, std::string& out) {
  out.reserve(out.size() + (bytes.size() + 2) / 3 * 4);
  const auto byte = [&](std::size_t k) { return static_cast<unsigned>(static_cast<unsigned char>(bytes[k])); };
  std::size_t i = 0;
  for (; i + 3 <= bytes.size(); i += 3) {
    const unsigned v = byte(i) << 16 | byte(i + 1) << 8 | byte(i + 2);
    out += {kAlphabet[v >> 18], kAlphabet[(v >> 12) & 63], kAlphabet[(v >> 6) & 63], kAlphabet[v & 63]};
  }
  if (bytes.size() - i == 1) {
    const unsigned v = byte(i) << 16;
    out += {kAlphabet[v >> 18], kAlphabet[(v >> 12) & 63], '=', '='};
  } else if (bytes.size() - i == 2) {
    const unsigned v = byte(i) << 16 | byte(i + 1) << 8;
    out += {kAlphabet[v >> 18], kAlphabet[(v >> 12) & 63], kAlphabet[(v >> 6) & 63], '='};
  }
}

bool Base64Decoder::decodeTo(std::string& out, std::size_t size, std::string& error) {
  while (out.size() < size) {
    unsigned group = 0;
    int filled = 0, padding = 0;
    while (filled < 4) {
      while (pos_ < text_.size() && isSpace(text_[pos_])) ++pos_;
      if (pos_ == text_.size()) {
        if (filled == 0) return true;
        error = fmt::format("the base64 text ends inside a group of four characters ({} left over)", filled);
        return false;
      }
      const char c = text_[pos_];
      const int value = kValues[static_cast<unsigned char>(c)];
      if (c == '=' && filled >= 2) {
        ++padding;  // completes a group of two or three characters
      } else if (value < 0 || padding > 0) {
        error = value < 0 && c != '=' ? fmt::format("invalid base64 character 0x{:02x} at character {}",
                                                    static_cast<unsigned char>(c), pos_)
                                      : fmt::format("misplaced '=' in base64 text at character {}", pos_);
        return false;
      }
      group = group << 6 | static_cast<unsigned>(value < 0 ? 0 : value);
      ++filled;
      ++pos_;
    }
    out += static_cast<char>(group >> 16);
    if (padding < 2) out += static_cast<char>((group >> 8) & 0xff);
    if (padding < 1) out += static_cast<char>(group & 0xff);
  }
  return true;
}

bool base64Decode(std::string_view text, std::string& out, std::string& error) {
  out.reserve(out.size() + text.size() / 4 * 3);
  return Base64Decoder(text).decodeTo(out, std::numeric_limits<std::size_t>::max(), error);
}

}  // namespace vrd::io
