#include "vrdeform/core/text_tokens.h"

#include <fmt/format.h>

#include <cmath>
#include <limits>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>

#include "vrdeform/error.h"

namespace vrd::io {

std::string readFileBytes(const std::filesystem::path& path) {
  std::error_code error;
  const auto status = std::filesystem::status(path, error);
  if (!std::filesystem::exists(status)) throw Error(fmt::format("cannot read {}: no such file", path.string()));
  if (std::filesystem::is_directory(status))
    throw Error(fmt::format("cannot read {}: it is a folder, not a file", path.string()));
  if (!std::filesystem::is_regular_file(status))
    throw Error(fmt::format("cannot read {}: not a regular file", path.string()));
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(fmt::format("cannot read {}: {}", path.string(), std::strerror(errno)));
  std::string bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  if (in.bad()) throw Error(fmt::format("cannot read {}: read failed", path.string()));
  return bytes;
}

std::string printable(std::string_view text) {
  std::string out;
  for (std::size_t i = 0; i < text.size() && i < 24; ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    if (c >= 0x20 && c < 0x7f)
      out += static_cast<char>(c);
    else
      out += fmt::format("\\x{:02x}", c);
  }
  if (text.size() > 24) out += "...";
  return out;
}

void splitWords(std::string_view line, std::vector<std::string_view>& words) {
  const auto blank = [](char c) { return c != '\n' && isSpace(c); };
  words.clear();
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && blank(line[i])) ++i;
    const std::size_t start = i;
    while (i < line.size() && !blank(line[i])) ++i;
    if (i > start) words.push_back(line.substr(start, i - start));
  }
}

bool parseInteger(std::string_view token, std::int64_t& value) {
  if (!token.empty() && token.front() == '+') token.remove_prefix(1);
  const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
  return ec == std::errc() && end == token.data() + token.size() && !token.empty();
}

bool parseReal(std::string_view token, double& value) {
  if (!token.empty() && token.front() == '+') token.remove_prefix(1);
  const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
  if (end != token.data() + token.size() || token.empty()) return false;
  // Out of range: from_chars leaves the value alone. An overflow becomes infinity (rejected later as
  // non-finite), an underflow zero.
  if (ec == std::errc::result_out_of_range) {
    const bool negative = token.front() == '-';
    const std::size_t e = token.find_first_of("eE");
    bool overflow;
    if (e != std::string_view::npos)
      overflow = e + 1 < token.size() && token[e + 1] != '-';
    else
      overflow = token.find_first_of("123456789") < token.find('.');
    value = overflow ? (negative ? -HUGE_VAL : HUGE_VAL) : (negative ? -0.0 : 0.0);
    return true;
  }
  return ec == std::errc();
}

TextTokens::TextTokens(std::string_view text, std::string name, char comment, std::size_t firstLine)
    : text_(text), name_(std::move(name)), comment_(comment), line_(firstLine), tokenLine_(firstLine) {}

void TextTokens::skipSpace() {
  while (pos_ < text_.size()) {
    const char c = text_[pos_];
    if (c == '\n') {
      ++line_;
      ++pos_;
    } else if (isSpace(c)) {
      ++pos_;
    } else if (comment_ != '\0' && c == comment_) {
      while (pos_ < text_.size() && text_[pos_] != '\n') ++pos_;
    } else {
      return;
    }
  }
}

bool TextTokens::atEnd() {
  skipSpace();
  return pos_ == text_.size();
}

std::string_view TextTokens::peek() {
  skipSpace();
  std::size_t end = pos_;
  while (end < text_.size() && !isSpace(text_[end]) && !(comment_ != '\0' && text_[end] == comment_)) ++end;
  return text_.substr(pos_, end - pos_);
}

std::string_view TextTokens::next(std::string_view expected) {
  const std::string_view token = peek();
  tokenLine_ = line_;
  if (token.empty()) fail(fmt::format("unexpected end of file, expected {}", expected));
  pos_ += token.size();
  return token;
}

std::int64_t TextTokens::integer(std::string_view what) {
  const std::string_view token = next(what);
  std::int64_t value = 0;
  if (!parseInteger(token, value)) fail(fmt::format("expected {} (an integer), found '{}'", what, printable(token)));
  return value;
}

std::int64_t TextTokens::integer(std::string_view what, std::int64_t lo, std::int64_t hi) {
  const std::int64_t value = integer(what);
  if (value < lo || value > hi) fail(fmt::format("{} is {}, expected {} to {}", what, value, lo, hi));
  return value;
}

double TextTokens::real(std::string_view what) { return realToken(what).first; }

std::pair<double, std::string_view> TextTokens::realToken(std::string_view what) {
  const std::string_view token = next(what);
  double value = 0;
  if (!parseReal(token, value)) fail(fmt::format("expected {} (a number), found '{}'", what, printable(token)));
  return {value, token};
}

float TextTokens::real32(std::string_view what) {
  const auto [value, token] = realToken(what);
  return toFloat(value, token, what);
}

float TextTokens::toFloat(double value, std::string_view token, std::string_view what) const {
  if (std::abs(value) > double(std::numeric_limits<float>::max()))
    fail(fmt::format("{} {} is out of range for a float (at most 3.4e38)", what, printable(token)));
  return static_cast<float>(value);
}

std::size_t TextTokens::count(std::string_view what, std::size_t tokensPerItem) {
  const std::int64_t n = integer(what);
  if (n < 0) fail(fmt::format("{} is negative ({})", what, n));
  checkFits(static_cast<std::uint64_t>(n), what, tokensPerItem);
  return static_cast<std::size_t>(n);
}

void TextTokens::checkFits(std::uint64_t n, std::string_view what, std::size_t tokensPerItem) {
  // Each token takes at least one character and one separator.
  const std::size_t fits = (remaining() + 1) / (2 * std::max<std::size_t>(tokensPerItem, 1));
  if (n > fits)
    fail(fmt::format("{} is {}, but the {} bytes left in the file can hold at most {}", what, n, remaining(), fits));
}

void TextTokens::skipLine() {
  while (pos_ < text_.size() && text_[pos_] != '\n') ++pos_;
  if (pos_ < text_.size()) {
    ++pos_;
    ++line_;
  }
}

std::string_view TextTokens::restOfLine() {
  tokenLine_ = line_;
  const std::size_t start = pos_;
  while (pos_ < text_.size() && text_[pos_] != '\n') ++pos_;
  std::string_view line = text_.substr(start, pos_ - start);
  if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
  if (pos_ < text_.size()) {
    ++pos_;
    ++line_;
  }
  return line;
}

void TextTokens::fail(std::string_view message) const {
  throw Error(fmt::format("{}:{}: {}", name_, tokenLine_, message));
}

}  // namespace vrd::io
