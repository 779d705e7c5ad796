// VTK XML unstructured grids (.vtu). A DataArray holds its numbers as text (format="ascii"), as
// base64 (format="binary") or at an offset into <AppendedData> (format="appended", raw bytes or
// base64). Binary data starts with a header of UInt32 or UInt64 numbers (header_type): the byte count,
// or with vtkZLibDataCompressor the block count, the block size, the last block's size and each
// block's compressed size, followed by the zlib blocks. Raw appended data is not XML, so it is cut out
// before the XML parser sees the file.

#include <fmt/format.h>
#include <zlib.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <limits>
#include <pugixml.hpp>

#include "io/base64.h"
#include "io/binary.h"
#include "io/tet_formats.h"
#include "io/text_out.h"
#include "io/xml_escape.h"
#include "vrdeform/core/text_tokens.h"
#include "vrdeform/error.h"

namespace vrd::io {
namespace {

// Deflate cannot compress by more than about 1032:1; a block claiming more is corrupt, and checking
// this bounds what a small file can make us allocate.
constexpr std::uint64_t kMaxInflateRatio = 1032;

// The bytes of one array's binary data: a view of raw appended bytes, or base64 decoded on demand.
class ArraySource {
 public:
  ArraySource(std::string_view data, bool base64) : data_(data), base64_(base64), decoder_(data) {}
  /// Most bytes the source could hold, for bounding counts before allocating.
  std::uint64_t bound() const { return base64_ ? data_.size() / 4 * 3 : data_.size(); }
  /// The first `n` bytes; false when there are fewer (`error` says why).
  bool first(std::size_t n, std::string_view& bytes, std::string& error) {
    if (!base64_) {
      if (n > data_.size()) {
        error = fmt::format("needs {} bytes, but only {} are there", n, data_.size());
        return false;
      }
      bytes = data_.substr(0, n);
      return true;
    }
    if (!decoder_.decodeTo(decoded_, n, error)) return false;
    if (decoded_.size() < n) {
      error = fmt::format("needs {} bytes, but the base64 text holds only {}", n, decoded_.size());
      return false;
    }
    bytes = std::string_view(decoded_).substr(0, n);
    return true;
  }

 private:
  std::string_view data_;
  bool base64_;
  Base64Decoder decoder_;
  std::string decoded_;
};

class VtuReader {
 public:
  VtuReader(std::string_view text, const std::string& name) : text_(text), name_(name) {}

  TetMesh read(std::vector<Triangle>* faces) {
    parse();
    const pugi::xml_node root = doc_.child("VTKFile");
    if (!root) fail(doc_, "no <VTKFile> element (not a VTK XML file)");
    const std::string_view type = root.attribute("type").value();
    if (type != "UnstructuredGrid")
      fail(root, fmt::format("VTKFile type '{}' is not supported, expected UnstructuredGrid", printable(type)));
    const std::string_view order = root.attribute("byte_order").value();
    if (order == "BigEndian") fail(root, "big-endian data (byte_order=\"BigEndian\") is not supported");
    if (!order.empty() && order != "LittleEndian") fail(root, fmt::format("unknown byte_order '{}'", printable(order)));
    const std::string_view header = root.attribute("header_type").value();
    if (header == "UInt64")
      headerSize_ = 8;
    else if (header.empty() || header == "UInt32")
      headerSize_ = 4;
    else
      fail(root, fmt::format("header_type '{}' is not supported (UInt32 or UInt64)", printable(header)));
    const std::string_view compressor = root.attribute("compressor").value();
    if (compressor == "vtkZLibDataCompressor")
      compressed_ = true;
    else if (!compressor.empty())
      fail(root, fmt::format("compressor '{}' is not supported (only vtkZLibDataCompressor)", printable(compressor)));
    if (const pugi::xml_node appended = root.child("AppendedData")) {
      const std::string_view encoding = appended.attribute("encoding").value();
      if (encoding != "raw" && encoding != "base64")
        fail(appended, fmt::format("AppendedData encoding '{}' is not supported (raw or base64)", printable(encoding)));
      appendedBase64_ = encoding == "base64";
    }

    const pugi::xml_node grid = root.child("UnstructuredGrid");
    if (!grid) fail(root, "no <UnstructuredGrid> element");
    TetMesh mesh;
    bool anyPiece = false;
    for (const pugi::xml_node piece : grid.children("Piece")) {
      readPiece(piece, mesh, faces);
      anyPiece = true;
    }
    if (!anyPiece) fail(grid, "no <Piece> element");
    return mesh;
  }

 private:
  [[noreturn]] void fail(const pugi::xml_node& node, std::string_view message) const {
    throw Error(fmt::format("{}:{}: {}", name_, lineOf(node), message));
  }
  std::size_t lineOf(const pugi::xml_node& node) const {
    const std::ptrdiff_t offset = node.offset_debug();
    if (offset < 0 || static_cast<std::size_t>(offset) > text_.size()) return 1;
    return 1 + static_cast<std::size_t>(std::count(text_.begin(), text_.begin() + offset, '\n'));
  }

  // Cuts raw appended data out of the file and parses the XML that remains.
  void parse() {
    if (text_.empty()) throw Error(fmt::format("{}: the file is empty", name_));
    std::string xml;
    const std::size_t tag = text_.find("<AppendedData");
    const std::size_t tagEnd = tag == std::string_view::npos ? tag : text_.find('>', tag);
    if (tag != std::string_view::npos && tagEnd == std::string_view::npos)
      throw Error(fmt::format("{}: the <AppendedData> tag is cut off", name_));
    if (tag == std::string_view::npos || text_[tagEnd - 1] == '/') {
      xml = text_;  // nothing appended
    } else {
      const std::size_t close = text_.rfind("</AppendedData>");
      if (close == std::string_view::npos || close <= tagEnd)
        throw Error(fmt::format("{}: no </AppendedData> after the appended data (truncated file?)", name_));
      std::size_t start = tagEnd + 1;
      while (start < close && std::isspace(static_cast<unsigned char>(text_[start]))) ++start;
      if (start < close) {
        if (text_[start] != '_') throw Error(fmt::format("{}: the appended data does not start with '_'", name_));
        appended_ = text_.substr(start + 1, close - start - 1);
        haveAppended_ = true;
      }
      xml.reserve(tagEnd + 1 + text_.size() - close);
      xml.append(text_.substr(0, tagEnd + 1));
      xml.append(text_.substr(close));
    }
    const pugi::xml_parse_result result = doc_.load_buffer(xml.data(), xml.size());
    if (!result) {
      const std::size_t at = std::min(static_cast<std::size_t>(std::max<std::ptrdiff_t>(result.offset, 0)), xml.size());
      const std::size_t line = 1 + static_cast<std::size_t>(std::count(xml.begin(), xml.begin() + at, '\n'));
      throw Error(fmt::format("{}:{}: XML error: {}", name_, line, result.description()));
    }
  }

  std::uint64_t count(const pugi::xml_node& node, const char* attribute) const {
    const std::string_view value = node.attribute(attribute).value();
    std::int64_t n = 0;
    if (!parseInteger(value, n) || n < 0 || n >= std::numeric_limits<Index>::max())
      fail(node, fmt::format("{}=\"{}\" is not a count", attribute, printable(value)));
    return static_cast<std::uint64_t>(n);
  }

  // The `count` numbers of a DataArray as T (double or std::int64_t).
  template <typename T>
  std::vector<T> numbers(const pugi::xml_node& array, std::uint64_t count) {
    const std::string what = fmt::format("DataArray '{}'", printable(array.attribute("Name").value()));
    const std::string_view typeName = array.attribute("type").value();
    const auto type = scalarFromXmlName(typeName);
    if (!type) fail(array, fmt::format("{}: unknown type '{}'", what, printable(typeName)));
    if constexpr (!std::is_floating_point_v<T>)
      if (isFloat(*type)) fail(array, fmt::format("{}: type {} is not an integer type", what, typeName));
    const std::string_view format = array.attribute("format").value();
    if (count > (std::uint64_t{1} << 56)) fail(array, fmt::format("{}: {} values are too many", what, count));
    std::vector<T> out;

    if (format == "ascii") {
      const pugi::xml_node data = array.first_child();
      const std::string_view text = data.type() == pugi::node_pcdata ? data.value() : "";
      TextTokens in(text, name_, '\0', lineOf(array));
      in.checkFits(count, what + " values", 1);
      out.resize(static_cast<std::size_t>(count));
      for (T& v : out) {
        if constexpr (std::is_floating_point_v<T>)
          v = in.real(what + " value");
        else
          v = in.integer(what + " value");
      }
      if (!in.atEnd()) in.fail(fmt::format("{} holds more than the {} values expected", what, count));
      return out;
    }

    std::string_view source;
    bool base64 = true;
    if (format == "binary") {
      source = array.text().get();
    } else if (format == "appended") {
      if (!haveAppended_) fail(array, fmt::format("{} is appended, but there is no <AppendedData>", what));
      const std::string_view offsetText = array.attribute("offset").value();
      std::int64_t offset = 0;
      if (!parseInteger(offsetText, offset) || offset < 0 || static_cast<std::uint64_t>(offset) > appended_.size())
        fail(array, fmt::format("{}: offset \"{}\" is not inside the {} bytes of appended data", what,
                                printable(offsetText), appended_.size()));
      source = appended_.substr(static_cast<std::size_t>(offset));
      base64 = appendedBase64_;
    } else {
      fail(array, fmt::format("{}: format '{}' is not supported (ascii, binary or appended)", what, printable(format)));
    }
    const std::size_t size = sizeOf(*type);
    ArraySource bytesSource(source, base64);
    const std::string bytes = binaryBytes(array, what, bytesSource, count * size);
    out.resize(static_cast<std::size_t>(count));
    const auto* p = reinterpret_cast<const unsigned char*>(bytes.data());
    for (std::size_t k = 0; k < out.size(); ++k) out[k] = loadScalar<T>(p + k * size, *type, false);
    return out;
  }

  // The data of a binary array without its header, inflated; it must be `expected` bytes.
  std::string binaryBytes(const pugi::xml_node& array, const std::string& what, ArraySource& source,
                          std::uint64_t expected) {
    std::string error;
    std::string_view bytes;
    const auto need = [&](std::uint64_t n, std::string_view part) {
      if (n > source.bound() || !source.first(static_cast<std::size_t>(n), bytes, error))
        fail(array, fmt::format("{}: {} is cut off or corrupt: {}", what, part,
                                error.empty() ? fmt::format("needs {} bytes, there are at most {}", n, source.bound())
                                              : error));
    };
    const std::size_t h = headerSize_;
    const auto headerValue = [&](std::size_t k) {
      return loadUnsigned(reinterpret_cast<const unsigned char*>(bytes.data()) + k * h, h, false);
    };
    if (!compressed_) {
      need(h, "the header");
      const std::uint64_t n = headerValue(0);
      if (n != expected) fail(array, fmt::format("{}: the header says {} bytes, expected {}", what, n, expected));
      need(h + n, "the data");
      return std::string(bytes.substr(h));
    }

    need(3 * h, "the compression header");
    const std::uint64_t blocks = headerValue(0), blockSize = headerValue(1), lastSize = headerValue(2);
    if (blocks > source.bound() / h) fail(array, fmt::format("{}: {} compressed blocks cannot fit", what, blocks));
    if (blocks == 0 && expected != 0)
      fail(array, fmt::format("{}: no compressed blocks, expected {} bytes", what, expected));
    if (blocks > 0) {
      const std::uint64_t last = lastSize == 0 ? blockSize : lastSize;
      if (blockSize == 0 || lastSize > blockSize || last > expected || blocks - 1 > expected / blockSize)
        fail(array, fmt::format("{}: {} blocks of {} bytes (the last {}) cannot hold the {} bytes expected", what,
                                blocks, blockSize, last, expected));
      const std::uint64_t total = (blocks - 1) * blockSize + last;
      if (total != expected)
        fail(array, fmt::format("{}: the compressed blocks hold {} bytes, expected {}", what, total, expected));
    }
    const std::size_t headerBytes = static_cast<std::size_t>((3 + blocks) * h);
    need(headerBytes, "the compression header");
    std::vector<std::uint64_t> sizes(static_cast<std::size_t>(blocks));
    std::uint64_t compressedTotal = 0;
    for (std::size_t b = 0; b < sizes.size(); ++b) {
      sizes[b] = headerValue(3 + b);
      const std::uint64_t inflated = b + 1 == sizes.size() && lastSize != 0 ? lastSize : blockSize;
      if (sizes[b] > source.bound() || inflated > kMaxInflateRatio * sizes[b] + 64)
        fail(array, fmt::format("{}: compressed block {} of {} bytes cannot inflate to {} bytes", what, b, sizes[b],
                                inflated));
      compressedTotal += sizes[b];
      if (compressedTotal > source.bound()) fail(array, fmt::format("{}: the compressed blocks cannot fit", what));
    }
    need(headerBytes + compressedTotal, "the compressed data");
    // Grown block by block, so that a corrupt block stops the reader before the memory for all of them
    // is taken.
    std::string out;
    std::size_t in = headerBytes, at = 0;
    for (std::size_t b = 0; b < sizes.size(); ++b) {
      const std::uint64_t inflated = b + 1 == sizes.size() && lastSize != 0 ? lastSize : blockSize;
      out.resize(at + static_cast<std::size_t>(inflated));
      uLongf produced = static_cast<uLongf>(inflated);
      const int rc = uncompress(reinterpret_cast<Bytef*>(out.data() + at), &produced,
                                reinterpret_cast<const Bytef*>(bytes.data() + in), static_cast<uLong>(sizes[b]));
      if (rc != Z_OK || produced != inflated)
        fail(array, fmt::format("{}: compressed block {} does not inflate to {} bytes ({})", what, b, inflated,
                                rc == Z_OK ? fmt::format("{} bytes", produced) : std::string(zError(rc))));
      in += static_cast<std::size_t>(sizes[b]);
      at += static_cast<std::size_t>(inflated);
    }
    return out;
  }

  pugi::xml_node dataArray(const pugi::xml_node& parent, std::string_view arrayName) const {
    for (const pugi::xml_node array : parent.children("DataArray"))
      if (arrayName.empty() || array.attribute("Name").value() == arrayName) return array;
    fail(parent, fmt::format("no DataArray{}{} in <{}>", arrayName.empty() ? "" : " named ", arrayName, parent.name()));
  }

  void readPiece(const pugi::xml_node& piece, TetMesh& mesh, std::vector<Triangle>* faces) {
    const std::uint64_t n = count(piece, "NumberOfPoints"), cells = count(piece, "NumberOfCells");
    const std::size_t base = mesh.vertices.size();
    if (base + n >= std::numeric_limits<Index>::max()) fail(piece, "too many points");
    if (n > 0) {
      const pugi::xml_node points = piece.child("Points");
      if (!points) fail(piece, "no <Points> element");
      const pugi::xml_node array = dataArray(points, "");
      if (array.attribute("NumberOfComponents").as_int(1) != 3)
        fail(array, "points must have NumberOfComponents=\"3\"");
      const std::vector<double> xyz = numbers<double>(array, 3 * n);
      mesh.vertices.resize(base + n);
      for (std::size_t v = 0; v < n; ++v) {
        Vec3& p = mesh.vertices[base + v];
        p = Vec3(static_cast<float>(xyz[3 * v]), static_cast<float>(xyz[3 * v + 1]),
                 static_cast<float>(xyz[3 * v + 2]));
        if (!isFinite(p))
          fail(array, fmt::format("point {} has a non-finite or out-of-range coordinate ({}, {}, {})", base + v,
                                  xyz[3 * v], xyz[3 * v + 1], xyz[3 * v + 2]));
      }
    }
    if (cells == 0) return;
    const pugi::xml_node cellNode = piece.child("Cells");
    if (!cellNode) fail(piece, "no <Cells> element");
    const pugi::xml_node offsetArray = dataArray(cellNode, "offsets");
    const std::vector<std::int64_t> offsets = numbers<std::int64_t>(offsetArray, cells);
    for (std::size_t c = 0; c < offsets.size(); ++c)
      if (offsets[c] < (c == 0 ? 0 : offsets[c - 1]))
        fail(offsetArray, fmt::format("cell offset {} ({}) is negative or smaller than the one before", c, offsets[c]));
    const std::vector<std::int64_t> connectivity =
        numbers<std::int64_t>(dataArray(cellNode, "connectivity"), static_cast<std::uint64_t>(offsets.back()));
    const pugi::xml_node typeArray = dataArray(cellNode, "types");
    const std::vector<std::int64_t> types = numbers<std::int64_t>(typeArray, cells);

    for (std::size_t c = 0; c < cells; ++c) {
      const std::int64_t type = types[c];
      if (type == kVtkQuadraticTet || type == kVtkLagrangeTet)
        fail(typeArray, fmt::format("second-order tets are not supported (cell {} has type {})", c, type));
      if (type != kVtkTet && type != kVtkTriangle) continue;
      const std::int64_t begin = c == 0 ? 0 : offsets[c - 1];
      const std::size_t size = type == kVtkTet ? 4 : 3;
      if (offsets[c] - begin != static_cast<std::int64_t>(size))
        fail(offsetArray,
             fmt::format("cell {} of type {} has {} points, expected {}", c, type, offsets[c] - begin, size));
      std::array<Index, 4> idx{};
      for (std::size_t k = 0; k < size; ++k) {
        const std::int64_t i = connectivity[static_cast<std::size_t>(begin) + k];
        if (i < 0 || static_cast<std::uint64_t>(i) >= n)
          fail(piece,
               fmt::format("cell {} refers to point {}, but the piece has {} points (numbered from 0)", c, i, n));
        idx[k] = static_cast<Index>(base + static_cast<std::size_t>(i));
      }
      if (type == kVtkTet)
        mesh.tets.push_back(idx);
      else if (faces)
        faces->push_back({idx[0], idx[1], idx[2]});
    }
  }

  std::string_view text_;
  const std::string& name_;
  pugi::xml_document doc_;
  std::string_view appended_;
  bool haveAppended_ = false, appendedBase64_ = false, compressed_ = false;
  std::size_t headerSize_ = 4;
};

// ---- writing

struct OutArray {
  std::string name;
  const char* type;
  int components;
  std::string bytes;  // little-endian values
  std::string ascii;  // the same as text
};

// Header + data, zlib-compressed in 32 KiB blocks when asked; `header` and `data` are kept apart
// because VTK base64-encodes them separately when compressed.
void encodeBinary(const std::string& bytes, bool compress, std::string& header, std::string& data) {
  if (!compress) {
    storeLittle<std::uint64_t>(header, bytes.size());
    data = bytes;
    return;
  }
  constexpr std::size_t kBlock = 1 << 15;
  const std::size_t blocks = (bytes.size() + kBlock - 1) / kBlock;
  storeLittle<std::uint64_t>(header, blocks);
  storeLittle<std::uint64_t>(header, kBlock);
  storeLittle<std::uint64_t>(header, bytes.size() % kBlock);
  std::string block;
  for (std::size_t b = 0; b < blocks; ++b) {
    const std::size_t size = std::min(kBlock, bytes.size() - b * kBlock);
    uLongf length = compressBound(static_cast<uLong>(size));
    block.resize(length);
    if (compress2(reinterpret_cast<Bytef*>(block.data()), &length,
                  reinterpret_cast<const Bytef*>(bytes.data() + b * kBlock), static_cast<uLong>(size),
                  Z_DEFAULT_COMPRESSION) != Z_OK)
      throw Error("zlib compression failed");
    storeLittle<std::uint64_t>(header, length);
    data.append(block.data(), length);
  }
}

}  // namespace

TetMesh readVtu(std::string_view text, const std::string& name, std::vector<Triangle>* faces) {
  return VtuReader(text, name).read(faces);
}

template <std::size_t N>
void writeVtu(std::ostream& stream, std::span<const Vec3> points, std::span<const std::array<Index, N>> cells,
              std::span<const VtuPointArray> pointData, const TetWriteOptions& options) {
  static_assert(N == 3 || N == 4);
  constexpr int kType = N == 4 ? 10 : 5;  // VTK_TETRA, VTK_TRIANGLE
  const bool ascii = options.vtuEncoding == VtuEncoding::Ascii;
  const bool compress = options.vtuCompress && !ascii;
  const auto vectors = [&](std::string_view name, std::span<const Vec3> values) {
    OutArray a{std::string(name), "Float32", 3, {}, {}};
    if (ascii) {
      fmt::memory_buffer text;
      for (const Vec3& v : values)
        fmt::format_to(std::back_inserter(text), "{:.9g} {:.9g} {:.9g}\n", v.x(), v.y(), v.z());
      a.ascii = fmt::to_string(text);
    } else {
      a.bytes.reserve(values.size() * 12);
      for (const Vec3& v : values)
        for (int c = 0; c < 3; ++c) storeLittle<float>(a.bytes, v[c]);
    }
    return a;
  };
  std::vector<OutArray> pointArrays;
  for (const VtuPointArray& p : pointData) pointArrays.push_back(vectors(p.name, p.values));
  OutArray position = vectors("Points", points);
  OutArray connectivity{"connectivity", "Int64", 1, {}, {}}, offsets{"offsets", "Int64", 1, {}, {}},
      types{"types", "UInt8", 1, {}, {}};
  if (ascii) {
    fmt::memory_buffer c, o;
    for (std::size_t t = 0; t < cells.size(); ++t) {
      fmt::format_to(std::back_inserter(c), "{}\n", fmt::join(cells[t], " "));
      fmt::format_to(std::back_inserter(o), "{}\n", N * (t + 1));
      types.ascii += fmt::format("{}\n", kType);
    }
    connectivity.ascii = fmt::to_string(c);
    offsets.ascii = fmt::to_string(o);
  } else {
    for (std::size_t t = 0; t < cells.size(); ++t) {
      for (Index i : cells[t]) storeLittle<std::int64_t>(connectivity.bytes, i);
      storeLittle<std::int64_t>(offsets.bytes, static_cast<std::int64_t>(N * (t + 1)));
      storeLittle<std::uint8_t>(types.bytes, kType);
    }
  }

  TextOut out(stream);
  std::string appended;
  const auto dataArray = [&](const OutArray& a, int indent) {
    out.print("{:{}}<DataArray type=\"{}\" Name=\"{}\"", "", indent, a.type, escapeXml(a.name));
    if (a.components != 1) out.print(" NumberOfComponents=\"{}\"", a.components);
    if (ascii) {
      out.print(" format=\"ascii\">\n{}{:{}}</DataArray>\n", a.ascii, "", indent);
      return;
    }
    std::string header, data;
    encodeBinary(a.bytes, compress, header, data);
    switch (options.vtuEncoding) {
      case VtuEncoding::AppendedRaw:
        out.print(" format=\"appended\" offset=\"{}\"/>\n", appended.size());
        appended += header;
        appended += data;
        break;
      case VtuEncoding::AppendedBase64:
        out.print(" format=\"appended\" offset=\"{}\"/>\n", appended.size());
        if (compress) {
          base64Encode(header, appended);
          base64Encode(data, appended);
        } else {
          base64Encode(header + data, appended);
        }
        break;
      default: {
        std::string text;
        if (compress) {
          base64Encode(header, text);
          base64Encode(data, text);
        } else {
          base64Encode(header + data, text);
        }
        out.print(" format=\"binary\">\n{:{}}{}\n{:{}}</DataArray>\n", "", indent + 2, text, "", indent);
      }
    }
  };

  out.print("<?xml version=\"1.0\"?>\n");
  out.print(
      "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\"{}>\n",
      compress ? " compressor=\"vtkZLibDataCompressor\"" : "");
  out.print("  <UnstructuredGrid>\n    <Piece NumberOfPoints=\"{}\" NumberOfCells=\"{}\">\n", points.size(),
            cells.size());
  if (!pointArrays.empty()) {
    out.print("      <PointData Vectors=\"{}\">\n", escapeXml(pointArrays[0].name));
    for (const OutArray& a : pointArrays) dataArray(a, 8);
    out.print("      </PointData>\n");
  }
  out.print("      <Points>\n");
  dataArray(position, 8);
  out.print("      </Points>\n      <Cells>\n");
  dataArray(connectivity, 8);
  dataArray(offsets, 8);
  dataArray(types, 8);
  out.print("      </Cells>\n    </Piece>\n  </UnstructuredGrid>\n");
  const bool appendedEncoding =
      options.vtuEncoding == VtuEncoding::AppendedRaw || options.vtuEncoding == VtuEncoding::AppendedBase64;
  if (appendedEncoding) {
    out.print("  <AppendedData encoding=\"{}\">\n   _",
              options.vtuEncoding == VtuEncoding::AppendedRaw ? "raw" : "base64");
    out.flush();
    stream.write(appended.data(), static_cast<std::streamsize>(appended.size()));
    out.print("\n  </AppendedData>\n");
  }
  out.print("</VTKFile>\n");
}

template void writeVtu<3>(std::ostream&, std::span<const Vec3>, std::span<const Triangle>,
                          std::span<const VtuPointArray>, const TetWriteOptions&);
template void writeVtu<4>(std::ostream&, std::span<const Vec3>, std::span<const Tet>, std::span<const VtuPointArray>,
                          const TetWriteOptions&);

}  // namespace vrd::io
