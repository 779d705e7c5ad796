#pragma once
// Base64 (RFC 4648, standard alphabet) as VTK XML files use it.

#include <string>
#include <string_view>

namespace vrd::io {

/// Appends the base64 encoding of `bytes` to `out`, padded with '='.
void base64Encode(std::string_view bytes, std::string& out);

/// Decodes base64 a group of four characters at a time, ignoring whitespace, so that a reader can
/// take a header first and then only as much data as the header says. Padding may also end a group
/// in the middle: VTK encodes a header and the data after it as two base64 strings written one after
/// the other, which decode to the bytes of both.
class Base64Decoder {
 public:
  explicit Base64Decoder(std::string_view text) : text_(text) {}
  /// Appends to `out` until it holds at least `size` bytes or the text ends. Returns false, with
  /// `error` saying why, for a character outside the alphabet, misplaced padding or a partial group.
  bool decodeTo(std::string& out, std::size_t size, std::string& error);
  bool atEnd() const { return pos_ == text_.size(); }

 private:
  std::string_view text_;
  std::size_t pos_ = 0;
};

/// All of `text`; see Base64Decoder.
bool base64Decode(std::string_view text, std::string& out, std::string& error);

}  // namespace vrd::io
