#include "marsala/terrain/asc_io.hpp"

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <climits>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <istream>
#include <limits>
#include <ostream>
#include <sstream>
#include <string_view>
#include <system_error>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "marsala/core/error.hpp"
#include "marsala/core/format.hpp"

namespace marsala::terrain {
namespace {

constexpr double kWrittenNodata = -9999.0;
constexpr const char* kFillHint = "fill NODATA cells explicitly (--fill-nodata) to accept this file";

bool is_blank(char ch) { return ch == ' ' || ch == '\t'; }

bool is_blank_line(std::string_view line) {
  for (char ch : line)
    if (!is_blank(ch)) return false;
  return true;
}

bool is_alpha(char ch) { return (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z'); }

char to_lower(char ch) { return (ch >= 'A' && ch <= 'Z') ? static_cast<char>(ch - 'A' + 'a') : ch; }

bool iequals(std::string_view a, std::string_view b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (to_lower(a[i]) != to_lower(b[i])) return false;
  return true;
}

// A token as it appears in a message: quoted, shortened, non-printable bytes escaped (binary files).
std::string quote(std::string_view token) {
  constexpr std::size_t kMax = 40;
  std::string out = "'";
  for (std::size_t i = 0; i < token.size() && i < kMax; ++i) {
    const auto ch = static_cast<unsigned char>(token[i]);
    if (ch >= 0x20 && ch < 0x7f) {
      out += static_cast<char>(ch);
    } else {
      static const char* kHex = "0123456789abcdef";
      out += "\\x";
      out += kHex[ch >> 4];
      out += kHex[ch & 0xf];
    }
  }
  if (token.size() > kMax) out += "...";
  return out + "'";
}

// A header number as the data rows write theirs: to_chars' shortest form, which is not fmt's "{}" (1e+06, not
// 1000000), so written files keep their bytes.
std::string format_double(double value) {
  char buf[64];
  const auto result = std::to_chars(buf, buf + sizeof buf, value);
  return std::string(buf, result.ptr);
}

enum class NumberStatus { kOk, kInvalid, kOutOfRange, kNonFinite };

// Parses a number starting at `first`; `*end` receives the end of the token (next blank or `last`).
// std::from_chars is locale-independent and allocates nothing.
NumberStatus parse_number(const char* first, const char* last, double& value, const char** end) {
  const char* p = first;
  if (p < last && *p == '+' && p + 1 < last && p[1] != '-' && p[1] != '+') ++p;
  const auto result = std::from_chars(p, last, value, std::chars_format::general);
  const char* token_end = result.ptr;
  const bool whole = result.ec != std::errc::invalid_argument && (token_end == last || is_blank(*token_end));
  if (!whole) {
    token_end = first;
    while (token_end < last && !is_blank(*token_end)) ++token_end;
  }
  *end = token_end;
  if (!whole) return NumberStatus::kInvalid;
  if (result.ec == std::errc::result_out_of_range) return NumberStatus::kOutOfRange;
  if (!std::isfinite(value)) return NumberStatus::kNonFinite;
  return NumberStatus::kOk;
}

// The header keys; xll/yll accept a corner or a centre spelling.
enum HeaderSlot { kNcols, kNrows, kXll, kYll, kCellsize, kNodata, kSlotCount };

struct HeaderEntry {
  bool seen = false;
  int line = 0;
  bool is_center = false;
  std::string key;  // as written in the file
  double value = 0.0;
};

class AscParser {
 public:
  AscParser(std::string_view text, const std::string& source, const AscReadOptions& options)
      : text_(text), source_(source), options_(options) {}

  Heightmap parse() {
    if (is_blank_text()) fail(1, "empty file: expected an ESRI ASCII grid header (ncols, nrows, ...)");
    std::string_view line;
    bool have_line = parse_header(line);
    return parse_data(have_line, line);
  }

 private:
  [[noreturn]] void fail(int line, const std::string& problem) const { throw ParseError(source_, line, problem); }

  bool is_blank_text() const {
    for (char ch : text_)
      if (!is_blank(ch) && ch != '\r' && ch != '\n') return false;
    return true;
  }

  // Next line without its terminator ('\n' or "\r\n"); false at the end of the text.
  bool next_line(std::string_view& line) {
    if (pos_ >= text_.size()) return false;
    const char* begin = text_.data() + pos_;
    const void* nl = std::memchr(begin, '\n', text_.size() - pos_);
    std::size_t length = nl ? static_cast<std::size_t>(static_cast<const char*>(nl) - begin) : text_.size() - pos_;
    pos_ += length + (nl ? 1 : 0);
    if (length > 0 && begin[length - 1] == '\r') --length;
    line = std::string_view(begin, length);
    ++line_no_;
    return true;
  }

  static std::string_view first_token(std::string_view line) {
    std::size_t b = 0;
    while (b < line.size() && is_blank(line[b])) ++b;
    std::size_t e = b;
    while (e < line.size() && !is_blank(line[e])) ++e;
    return line.substr(b, e - b);
  }

  // A header line starts with a word that is not a number (so "nan" / "inf" rows stay data rows).
  static bool is_header_line(std::string_view line) {
    const std::string_view token = first_token(line);
    if (token.empty() || !is_alpha(token.front())) return false;
    double value = 0.0;
    const char* end = nullptr;
    return parse_number(token.data(), token.data() + token.size(), value, &end) == NumberStatus::kInvalid;
  }

  static int slot_of(std::string_view key, bool& is_center) {
    is_center = false;
    if (iequals(key, "ncols")) return kNcols;
    if (iequals(key, "nrows")) return kNrows;
    if (iequals(key, "xllcorner")) return kXll;
    if (iequals(key, "yllcorner")) return kYll;
    is_center = iequals(key, "xllcenter") || iequals(key, "yllcenter");
    if (iequals(key, "xllcenter")) return kXll;
    if (iequals(key, "yllcenter")) return kYll;
    if (iequals(key, "cellsize")) return kCellsize;
    if (iequals(key, "nodata_value")) return kNodata;
    return -1;
  }

  void parse_header_line(std::string_view line) {
    std::size_t b = 0;
    while (b < line.size() && is_blank(line[b])) ++b;
    std::size_t e = b;
    while (e < line.size() && !is_blank(line[e])) ++e;
    const std::string_view key = line.substr(b, e - b);
    bool is_center = false;
    const int slot = slot_of(key, is_center);
    if (slot < 0)
      fail(line_no_, fmt::format("unknown header key {} (expected ncols, nrows, xllcorner|xllcenter, "
                                 "yllcorner|yllcenter, cellsize, NODATA_value)",
                                 quote(key)));
    HeaderEntry& entry = header_[slot];
    if (entry.seen)
      fail(line_no_, fmt::format("duplicate header key {} (already given as {} on line {})", quote(key),
                                 quote(entry.key), entry.line));
    while (e < line.size() && is_blank(line[e])) ++e;
    if (e == line.size()) fail(line_no_, fmt::format("header key {} has no value", quote(key)));
    double value = 0.0;
    const char* end = nullptr;
    const char* first = line.data() + e;
    const char* last = line.data() + line.size();
    const NumberStatus status = parse_number(first, last, value, &end);
    const std::string_view token(first, static_cast<std::size_t>(end - first));
    if (status == NumberStatus::kInvalid)
      fail(line_no_, fmt::format("value of header key {} is not a number: {}", quote(key), quote(token)));
    if (status == NumberStatus::kOutOfRange)
      fail(line_no_, fmt::format("value of header key {} is out of range: {}", quote(key), quote(token)));
    if (status == NumberStatus::kNonFinite)
      fail(line_no_, fmt::format("value of header key {} must be finite, got {}", quote(key), quote(token)));
    for (const char* p = end; p < last; ++p)
      if (!is_blank(*p))
        fail(line_no_, fmt::format("trailing garbage after the value of header key {}: {}", quote(key),
                                   quote(std::string_view(p, static_cast<std::size_t>(last - p)))));
    if (slot == kNcols || slot == kNrows) {
      long long integer = 0;
      const auto result = std::from_chars(token.data(), token.data() + token.size(), integer);
      if (result.ec != std::errc() || result.ptr != token.data() + token.size())
        fail(line_no_, fmt::format("header key {} must be a positive integer, got {}", quote(key), quote(token)));
      if (integer <= 0) fail(line_no_, fmt::format("header key {} must be positive, got {}", quote(key), quote(token)));
      if (integer > INT_MAX) fail(line_no_, fmt::format("header key {} is too large: {}", quote(key), quote(token)));
    }
    if (slot == kCellsize && !(value > 0.0))
      fail(line_no_, fmt::format("header key {} must be positive, got {}", quote(key), quote(token)));
    entry.seen = true;
    entry.line = line_no_;
    entry.is_center = is_center;
    entry.key = std::string(key);
    entry.value = value;
  }

  // Reads header lines; returns true with `line` holding the first data line, false at the end of the text.
  bool parse_header(std::string_view& line) {
    while (next_line(line)) {
      if (is_blank_line(line)) fail(line_no_, "empty line in the header");
      if (!is_header_line(line)) {
        check_header_complete(line_no_, "before the first data row");
        return true;
      }
      parse_header_line(line);
    }
    check_header_complete(line_no_ + 1, "and no data rows follow");
    return false;
  }

  void check_header_complete(int line, const char* where) const {
    static const char* kNames[] = {"ncols", "nrows", "xllcorner (or xllcenter)", "yllcorner (or yllcenter)",
                                   "cellsize"};
    for (int slot = kNcols; slot < kNodata; ++slot)
      if (!header_[slot].seen) fail(line, fmt::format("missing header key '{}' {}", kNames[slot], where));
  }

  Heightmap parse_data(bool have_line, std::string_view line) {
    const int rows = static_cast<int>(header_[kNrows].value);
    const int cols = static_cast<int>(header_[kNcols].value);
    const double cell_size = header_[kCellsize].value;
    const bool has_nodata = header_[kNodata].seen;
    const double nodata = header_[kNodata].value;

    // A valid file holds at most (bytes + 1) / 2 values, so this never reserves more than the data can fill,
    // whatever the header claims.
    const long long announced = static_cast<long long>(rows) * cols;
    const long long remaining = static_cast<long long>(text_.size() - pos_ + line.size() + 1);
    std::vector<double> heights;
    heights.reserve(static_cast<std::size_t>(std::min(announced, remaining / 2 + 1)));

    int row = 0;
    int pending_blank_line = 0;
    long long nodata_cells = 0;
    for (; have_line; have_line = next_line(line)) {
      if (is_blank_line(line)) {
        if (pending_blank_line == 0) pending_blank_line = line_no_;
        continue;
      }
      if (row == rows) reject_extra_content(line, rows);
      if (pending_blank_line != 0)
        fail(pending_blank_line,
             fmt::format("empty line where data row {} of {} was expected (one row per line)", row + 1, rows));
      // A line of L characters holds at most (L + 1) / 2 values: never grow by more than that, whatever
      // ncols claims (a row that cannot fit is reported as too short below).
      const std::size_t base = heights.size();
      heights.resize(base + std::min(static_cast<std::size_t>(cols), (line.size() + 1) / 2));
      double* out = heights.data() + base;
      const char* p = line.data();
      const char* last = p + line.size();
      int col = 0;
      for (;;) {
        while (p < last && is_blank(*p)) ++p;
        if (p == last) break;
        if (col == cols)
          fail(line_no_, fmt::format("too many values on data row {}: expected {} (ncols)", row + 1, cols));
        double value = 0.0;
        const char* end = nullptr;
        const NumberStatus status = parse_number(p, last, value, &end);
        if (status != NumberStatus::kOk) reject_value(status, std::string_view(p, end - p), row, col);
        if (has_nodata && value == nodata) {
          if (!options_.fill_nodata && !options_.keep_nodata)
            fail(line_no_, fmt::format("NODATA value {} at data row {}, column {}; {}",
                                       quote(std::string_view(p, end - p)), row + 1, col + 1, kFillHint));
          value = std::numeric_limits<double>::quiet_NaN();
          ++nodata_cells;
        }
        out[col++] = value;
        p = end;
      }
      if (col < cols)
        fail(line_no_, fmt::format("too few values on data row {}: got {}, expected {} (ncols)", row + 1, col, cols));
      ++row;
    }
    if (row < rows)
      fail(pending_blank_line != 0 ? pending_blank_line : line_no_ + 1,
           fmt::format("too few data rows: got {}, expected {} (nrows)", row, rows));

    GridGeometry geometry;
    geometry.rows = rows;
    geometry.cols = cols;
    geometry.cell_size_m = cell_size;
    geometry.xll_m = header_[kXll].value - (header_[kXll].is_center ? 0.5 * cell_size : 0.0);
    geometry.yll_m = header_[kYll].value - (header_[kYll].is_center ? 0.5 * cell_size : 0.0);
    // A centre near the double limits puts the corner half a cell beyond them.
    for (const auto& [slot, corner] : {std::pair{kXll, geometry.xll_m}, std::pair{kYll, geometry.yll_m}})
      if (!std::isfinite(corner))
        fail(header_[slot].line,
             fmt::format("header key {} puts the grid's lower-left corner half a cell beyond the range of doubles",
                         quote(header_[slot].key)));
    Heightmap map(geometry, HeightMatrix(Eigen::Map<const HeightMatrix>(heights.data(), rows, cols)));
    if (nodata_cells > 0 && !options_.keep_nodata) {
      if (nodata_cells == announced) fail(0, "every cell is NODATA; there is nothing to fill from");
      fill_nodata(map);
    }
    return map;
  }

  [[noreturn]] void reject_value(NumberStatus status, std::string_view token, int row, int col) const {
    const char* what = status == NumberStatus::kNonFinite    ? "non-finite height "
                       : status == NumberStatus::kOutOfRange ? "height out of range "
                                                             : "not a number: ";
    fail(line_no_, fmt::format("{}{} at data row {}, column {}", what, quote(token), row + 1, col + 1));
  }

  [[noreturn]] void reject_extra_content(std::string_view line, int rows) const {
    const std::string_view token = first_token(line);
    double value = 0.0;
    const char* end = nullptr;
    if (parse_number(token.data(), token.data() + token.size(), value, &end) == NumberStatus::kOk)
      fail(line_no_, fmt::format("too many data rows: expected {} (nrows)", rows));
    fail(line_no_, fmt::format("trailing garbage after the last data row: {}", quote(line)));
  }

  std::string_view text_;
  const std::string& source_;
  const AscReadOptions& options_;
  std::size_t pos_ = 0;
  int line_no_ = 0;
  HeaderEntry header_[kSlotCount];
};

std::string read_stream(std::istream& in, const std::string& source_name) {
  std::ostringstream buffer;
  if (in.peek() != std::char_traits<char>::eof()) buffer << in.rdbuf();
  if (in.bad()) throw IoError(fmt::format("cannot read '{}'", source_name));
  return std::move(buffer).str();
}

void check_writable(const Heightmap& map) {
  if (map.rows() <= 0 || map.cols() <= 0) throw InvalidArgument("write_asc: the heightmap is empty");
  const GridGeometry& g = map.geometry();
  if (!std::isfinite(g.xll_m) || !std::isfinite(g.yll_m) || !std::isfinite(g.cell_size_m) || !(g.cell_size_m > 0))
    throw InvalidArgument("write_asc: the grid geometry must be finite with a positive cell size");
  for (int r = 0; r < map.rows(); ++r)
    for (int c = 0; c < map.cols(); ++c) {
      const double h = map(r, c);
      if (std::isinf(h)) throw InvalidArgument(fmt::format("write_asc: infinite height at cell {}", CellIndex{r, c}));
      if (h == kWrittenNodata)
        throw InvalidArgument(
            fmt::format("write_asc: height -9999 at cell {} would read back as NODATA_value -9999", CellIndex{r, c}));
    }
}

void emit(const Heightmap& map, std::ostream& out) {
  std::string buffer = fmt::format("ncols {}\nnrows {}\nxllcorner {}\nyllcorner {}\ncellsize {}\nNODATA_value -9999\n",
                                   map.cols(), map.rows(), format_double(map.geometry().xll_m),
                                   format_double(map.geometry().yll_m), format_double(map.cell_size_m()));
  constexpr std::size_t kFlushBytes = 1 << 20;
  buffer.reserve(kFlushBytes + 64);
  char number[64];
  for (int r = 0; r < map.rows(); ++r) {
    for (int c = 0; c < map.cols(); ++c) {
      if (c > 0) buffer += ' ';
      const double h = map(r, c);
      const auto result = std::to_chars(number, number + sizeof number, std::isnan(h) ? kWrittenNodata : h);
      buffer.append(number, result.ptr);
      if (buffer.size() >= kFlushBytes) {
        out.write(buffer.data(), static_cast<std::streamsize>(buffer.size()));
        buffer.clear();
      }
    }
    buffer += '\n';
  }
  out.write(buffer.data(), static_cast<std::streamsize>(buffer.size()));
  out.flush();
}

}  // namespace

Heightmap parse_asc(std::istream& in, const std::string& source_name, const AscReadOptions& options) {
  const std::string text = read_stream(in, source_name);
  return AscParser(text, source_name, options).parse();
}

Heightmap read_asc(const std::string& path, const AscReadOptions& options) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw IoError(fmt::format("cannot read '{}': it is a directory", path));
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IoError(fmt::format("cannot open '{}': {}", path, std::strerror(errno)));
  in.seekg(0, std::ios::end);
  const std::streamoff size = in.tellg();
  in.seekg(0, std::ios::beg);
  if (size < 0) throw IoError(fmt::format("cannot read '{}'", path));
  std::string text(static_cast<std::size_t>(size), '\0');
  in.read(text.data(), size);
  if (in.gcount() != size) throw IoError(fmt::format("cannot read '{}': short read", path));
  return AscParser(text, path, options).parse();
}

void write_asc(const Heightmap& map, std::ostream& out) {
  check_writable(map);
  emit(map, out);
  if (!out) throw IoError("failed to write the ESRI ASCII grid to the output stream");
}

void write_asc(const Heightmap& map, const std::string& path) {
  check_writable(map);
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) throw IoError(fmt::format("cannot open '{}' for writing: {}", path, std::strerror(errno)));
  emit(map, out);
  out.close();
  if (!out) throw IoError(fmt::format("failed to write '{}'", path));
}

void fill_nodata(Heightmap& map) {
  const int rows = map.rows();
  const int cols = map.cols();
  const long long cells = map.size();
  if (cells <= 0) throw InvalidArgument("fill_nodata: the heightmap is empty");
  double* h = map.data();
  // 0 = known, 1 = missing, 2 = missing and in the current or next layer.
  std::vector<std::uint8_t> state(static_cast<std::size_t>(cells), 0);
  long long missing = 0;
  for (long long i = 0; i < cells; ++i)
    if (std::isnan(h[i])) {
      state[i] = 1;
      ++missing;
    }
  if (missing == 0) return;
  if (missing == cells)
    throw InvalidArgument(fmt::format("fill_nodata: all {} cells are NODATA; nothing to fill from", cells));

  auto for_neighbours = [&](long long i, auto&& visit) {
    const int r = static_cast<int>(i / cols);
    const int c = static_cast<int>(i % cols);
    for (int dr = -1; dr <= 1; ++dr)
      for (int dc = -1; dc <= 1; ++dc) {
        if (dr == 0 && dc == 0) continue;
        const int nr = r + dr;
        const int nc = c + dc;
        if (nr >= 0 && nr < rows && nc >= 0 && nc < cols) visit(static_cast<long long>(nr) * cols + nc);
      }
  };

  std::vector<long long> layer;
  for (long long i = 0; i < cells; ++i) {
    if (state[i] != 1) continue;
    bool touches_known = false;
    for_neighbours(i, [&](long long j) { touches_known |= state[j] == 0; });
    if (touches_known) {
      state[i] = 2;
      layer.push_back(i);
    }
  }
  std::vector<double> values;
  std::vector<long long> next;
  while (!layer.empty()) {
    // Compute the whole layer before writing it, so a cell never sees a neighbour of its own layer.
    values.resize(layer.size());
    for (std::size_t k = 0; k < layer.size(); ++k) {
      double sum = 0.0;
      int count = 0;
      for_neighbours(layer[k], [&](long long j) {
        if (state[j] == 0) {
          sum += h[j];
          ++count;
        }
      });
      values[k] = sum / count;
      if (!std::isfinite(values[k])) {
        // Heights near the double limits overflow the sum; scaled by 1/8 (exact) they cannot, and the mean is the same.
        sum = 0.0;
        for_neighbours(layer[k], [&](long long j) {
          if (state[j] == 0) sum += h[j] * 0.125;
        });
        values[k] = sum / count * 8.0;
      }
    }
    for (std::size_t k = 0; k < layer.size(); ++k) h[layer[k]] = values[k];
    for (long long i : layer) state[i] = 0;
    next.clear();
    for (long long i : layer)
      for_neighbours(i, [&](long long j) {
        if (state[j] == 1) {
          state[j] = 2;
          next.push_back(j);
        }
      });
    layer.swap(next);
  }
}

}  // namespace marsala::terrain
