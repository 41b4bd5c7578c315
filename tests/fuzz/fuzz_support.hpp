#pragma once
// A small deterministic mutation fuzzer for the fuzz tests (tests/fuzz/README.md): seeded std::mt19937_64, byte and
// token mutations of text and binary inputs, a budget of iterations, a watchdog that bounds each call, and failure
// reports that name the seed, the iteration and the input (also saved to a file to replay).

#include <gtest/gtest.h>

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <mutex>
#include <optional>
#include <random>
#include <string>
#include <thread>
#include <type_traits>
#include <typeinfo>
#include <vector>

namespace marsala::fuzz {

/// Runs load() on one fuzzed input: what it loaded, or nullopt when it refused the input with an `Expected` (whose
/// message `check` examines). Anything else thrown is a failure: readers answer bad input with the project's typed
/// errors only. `expected` names the type in the failure message.
template <typename Expected, typename Load, typename Check, typename Report>
auto load_or_refuse(Load&& load, Check&& check, const char* expected, const Report& report)
    -> std::optional<std::decay_t<decltype(load())>> {
  try {
    return load();
  } catch (const Expected& e) {
    check(e);
  } catch (const std::exception& e) {
    ADD_FAILURE() << "not a " << expected << ": " << typeid(e).name() << ": " << e.what() << "\n" << report();
  } catch (...) {
    ADD_FAILURE() << "a non-exception was thrown\n" << report();
  }
  return std::nullopt;
}

/// MARSALA_SOURCE_DIR (set by ctest), else ".".
inline std::string source_dir() {
  const char* dir = std::getenv("MARSALA_SOURCE_DIR");
  return dir ? dir : ".";
}

/// Iterations for a target: `base`, times MARSALA_FUZZ_SCALE when set (a longer local run, e.g. 20); at least 1.
inline int iterations(int base) {
  const char* scale = std::getenv("MARSALA_FUZZ_SCALE");
  const double factor = scale ? std::atof(scale) : 1.0;
  const double n = factor > 0.0 ? base * factor : base;
  return n < 1.0 ? 1 : n > 1e9 ? 1000000000 : static_cast<int>(n);
}

/// The seed of a target: `fixed`, or MARSALA_FUZZ_SEED when set (to explore beyond the CI corpus).
inline std::uint64_t seed(std::uint64_t fixed) {
  const char* text = std::getenv("MARSALA_FUZZ_SEED");
  return text ? std::strtoull(text, nullptr, 10) : fixed;
}

/// The bytes of a file; empty when it cannot be read.
inline std::string read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

/// Writes `bytes` to `path`; fails the test when it cannot.
inline void write_file(const std::string& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  out.close();
  if (!out) ADD_FAILURE() << "cannot write " << path;
}

/// `bytes` as a C string literal, shortened to `max` bytes, for failure messages.
inline std::string escaped(const std::string& bytes, std::size_t max = 1500) {
  std::string out = "\"";
  for (std::size_t i = 0; i < bytes.size() && i < max; ++i) {
    const auto ch = static_cast<unsigned char>(bytes[i]);
    if (ch == '\n') {
      out += "\\n";
    } else if (ch == '\\' || ch == '"') {
      out += '\\';
      out += static_cast<char>(ch);
    } else if (ch >= 0x20 && ch < 0x7f) {
      out += static_cast<char>(ch);
    } else {
      char hex[8];
      std::snprintf(hex, sizeof hex, "\\x%02x", ch);
      out += hex;
    }
  }
  out += bytes.size() > max ? "\"..." : "\"";
  return out;
}

/// Doubles that break careless code: NaN, infinities, extremes, subnormals, signed zero, values next to limits.
inline const std::vector<double>& nasty_doubles() {
  static const std::vector<double> kValues = {
      std::numeric_limits<double>::quiet_NaN(),
      -std::numeric_limits<double>::quiet_NaN(),
      std::numeric_limits<double>::infinity(),
      -std::numeric_limits<double>::infinity(),
      std::numeric_limits<double>::max(),
      std::numeric_limits<double>::lowest(),
      std::numeric_limits<double>::min(),
      std::numeric_limits<double>::denorm_min(),
      -std::numeric_limits<double>::denorm_min(),
      0.0,
      -0.0,
      1e308,
      -1e308,
      1e6,
      -1e6,
      999999.9999999999,
      1e-300,
      -1.0,
      1.0,
      1.0 + 1e-9,
      2147483648.0,
      -9999.0,
      1e-12,
  };
  return kValues;
}

/// Number spellings for text formats: the nasty doubles and the ways a parser can misread a number.
inline const std::vector<std::string>& nasty_numbers() {
  static const std::vector<std::string> kTokens = {"nan",
                                                   "NaN",
                                                   "-nan",
                                                   "inf",
                                                   "-inf",
                                                   "Infinity",
                                                   "1e308",
                                                   "-1e308",
                                                   "1.7976931348623157e308",
                                                   "1.8e308",
                                                   "-1.8e308",
                                                   "4.9e-324",
                                                   "2.2250738585072014e-308",
                                                   "1e-400",
                                                   "1e100000",
                                                   "-0",
                                                   "-0.0",
                                                   "0",
                                                   "0x1p3",
                                                   "1e6",
                                                   "-1e6",
                                                   "999999.99",
                                                   "2147483647",
                                                   "2147483648",
                                                   "-2147483648",
                                                   "4294967295",
                                                   "4294967296",
                                                   "9223372036854775807",
                                                   "18446744073709551616",
                                                   "-9999",
                                                   "-9999.0",
                                                   "+5",
                                                   "++5",
                                                   "+-5",
                                                   "5e",
                                                   ".",
                                                   "-",
                                                   "1.",
                                                   ".5",
                                                   "00012",
                                                   "1_000",
                                                   "1e-9",
                                                   "0.0125",
                                                   "3",
                                                   "1",
                                                   "2"};
  return kTokens;
}

/// Seeded mutations of byte strings. Text mutations splice tokens and numbers; binary ones overwrite integers.
class Mutator {
 public:
  /// `dictionary`: tokens of the format (keywords, punctuation) spliced into text inputs.
  Mutator(std::uint64_t seed, std::vector<std::string> dictionary) : rng_(seed), dictionary_(std::move(dictionary)) {}

  std::mt19937_64& rng() { return rng_; }
  /// Uniform in [0, n); 0 when n is 0.
  /// Keeps an accepted `input` as a seed, so that later mutations reach beyond the header checks: appended while the
  /// corpus holds fewer than `max` entries, else in place of a random entry after the first `fixed` ones.
  void keep(std::vector<std::string>& corpus, const std::string& input, std::size_t fixed, std::size_t max) {
    if (corpus.size() < max)
      corpus.push_back(input);
    else
      corpus[fixed + below(max - fixed)] = input;
  }
  std::size_t below(std::size_t n) { return n == 0 ? 0 : std::uniform_int_distribution<std::size_t>(0, n - 1)(rng_); }
  bool chance(double p) { return std::uniform_real_distribution<double>(0.0, 1.0)(rng_) < p; }
  template <typename T>
  const T& pick(const std::vector<T>& values) {
    return values[below(values.size())];
  }

  /// 1 to 4 stacked text mutations of `input`; `corpus` supplies splices.
  std::string mutate_text(std::string input, const std::vector<std::string>& corpus) {
    const int rounds = 1 + static_cast<int>(below(4));
    for (int i = 0; i < rounds; ++i) mutate_text_once(input, corpus);
    return input;
  }

  /// 1 to 4 stacked binary mutations of `input`; `corpus` supplies splices.
  std::string mutate_binary(std::string input, const std::vector<std::string>& corpus) {
    const int rounds = 1 + static_cast<int>(below(4));
    for (int i = 0; i < rounds; ++i) mutate_binary_once(input, corpus);
    return input;
  }

 private:
  std::size_t position(const std::string& s) { return below(s.size() + 1); }

  // Bytes that end tokens, lines or numbers.
  char special_byte() {
    static const char kBytes[] = {' ', '\n', '\r', '\t', '\0', '-', '+', '.', 'e', '0', '9', '{', '}', ':', '"', '#'};
    return kBytes[below(sizeof kBytes)];
  }

  void flip_bit(std::string& s) {
    if (!s.empty()) s[below(s.size())] ^= static_cast<char>(1u << below(8));
  }
  void set_byte(std::string& s) {
    if (s.empty()) return;
    s[below(s.size())] = chance(0.5) ? special_byte() : static_cast<char>(below(256));
  }
  void insert_bytes(std::string& s) {
    std::string bytes;
    for (std::size_t n = 1 + below(8); n > 0; --n)
      bytes += chance(0.5) ? special_byte() : static_cast<char>(below(256));
    s.insert(position(s), bytes);
  }
  void erase_range(std::string& s) {
    if (s.empty()) return;
    const std::size_t at = below(s.size());
    s.erase(at, 1 + below(chance(0.8) ? 16 : 256));
  }
  void duplicate_range(std::string& s) {
    if (s.empty()) return;
    const std::size_t at = below(s.size());
    const std::string chunk = s.substr(at, 1 + below(chance(0.8) ? 32 : 512));
    std::string copies;
    for (std::size_t n = chance(0.9) ? 1 : 2 + below(20); n > 0; --n) copies += chunk;
    s.insert(position(s), copies);
  }
  void splice(std::string& s, const std::vector<std::string>& corpus) {
    if (corpus.empty()) return;
    const std::string& other = pick(corpus);
    s = s.substr(0, position(s)) + other.substr(below(other.size() + 1));
  }
  void truncate(std::string& s) { s.resize(below(s.size() + 1)); }

  // The span [begin, end) of a number-like run (digits, sign, point, exponent) around a random digit, if any.
  bool find_number(const std::string& s, std::size_t& begin, std::size_t& end) {
    if (s.empty()) return false;
    const std::size_t start = below(s.size());
    for (std::size_t k = 0; k < s.size(); ++k) {
      const std::size_t i = (start + k) % s.size();
      if (s[i] < '0' || s[i] > '9') continue;
      const auto numeric = [](char c) {
        return (c >= '0' && c <= '9') || c == '.' || c == '-' || c == '+' || c == 'e';
      };
      begin = i;
      while (begin > 0 && numeric(s[begin - 1])) --begin;
      end = i;
      while (end < s.size() && numeric(s[end])) ++end;
      return true;
    }
    return false;
  }

  void mutate_text_once(std::string& s, const std::vector<std::string>& corpus) {
    switch (below(12)) {
      case 0: flip_bit(s); break;
      case 1: set_byte(s); break;
      case 2: insert_bytes(s); break;
      case 3: erase_range(s); break;
      case 4: duplicate_range(s); break;
      case 5: splice(s, corpus); break;
      case 6: truncate(s); break;
      case 7:
      case 8: {  // a number replaced by a nasty spelling
        std::size_t begin = 0, end = 0;
        if (find_number(s, begin, end))
          s.replace(begin, end - begin, pick(nasty_numbers()));
        else
          s.insert(position(s), pick(nasty_numbers()));
        break;
      }
      case 9: {  // a token of the format, alone or with a number
        std::string token = dictionary_.empty() ? std::string(" ") : pick(dictionary_);
        if (chance(0.5)) token = " " + token + " " + pick(nasty_numbers()) + (chance(0.5) ? "\n" : " ");
        s.insert(position(s), token);
        break;
      }
      case 10: {  // a whole line of the input or of another corpus entry repeated or moved
        const std::string& from = corpus.empty() || chance(0.5) ? s : pick(corpus);
        if (from.empty()) break;
        std::size_t b = from.rfind('\n', below(from.size()));
        b = b == std::string::npos ? 0 : b + 1;
        std::size_t e = from.find('\n', b);
        e = e == std::string::npos ? from.size() : e + 1;
        const std::string line = from.substr(b, e - b);
        std::size_t at = s.rfind('\n', position(s));
        at = at == std::string::npos ? 0 : at + 1;
        s.insert(at, line);
        break;
      }
      default: {  // line endings and separators swapped
        std::size_t begin = 0, end = 0;
        if (!find_number(s, begin, end)) break;
        if (end < s.size()) s[end] = special_byte();
        break;
      }
    }
  }

  void overwrite_integer(std::string& s) {
    static const std::uint64_t kValues[] = {0,       1,          2,          3,          7,          8,         16,
                                            0x7f,    0x80,       0xff,       0x100,      0x7fff,     0x8000,    0xffff,
                                            0x10000, 0x7fffffff, 0x80000000, 0xffffffff, 0x40000000, 0x00010001};
    if (s.empty()) return;
    const std::size_t width = std::size_t{1} << below(3);  // 1, 2 or 4 bytes
    std::uint64_t value = chance(0.8) ? kValues[below(sizeof kValues / sizeof kValues[0])] : rng_();
    if (chance(0.3)) value = s.size() + below(16) - 8;  // offsets near the end of the file
    const std::size_t at = below(s.size());
    const bool big_endian = chance(0.5);
    for (std::size_t i = 0; i < width && at + i < s.size(); ++i) {
      const std::size_t shift = 8 * (big_endian ? width - 1 - i : i);
      s[at + i] = static_cast<char>((value >> shift) & 0xff);
    }
  }
  void overwrite_double(std::string& s) {
    if (s.size() < 8) return;
    const double value = pick(nasty_doubles());
    std::memcpy(&s[below(s.size() - 7)], &value, sizeof value);
  }

  void mutate_binary_once(std::string& s, const std::vector<std::string>& corpus) {
    switch (below(10)) {
      case 0:
      case 1: flip_bit(s); break;
      case 2: set_byte(s); break;
      case 3:
      case 4:
      case 5: overwrite_integer(s); break;
      case 6: overwrite_double(s); break;
      case 7: erase_range(s); break;
      case 8: chance(0.5) ? truncate(s) : insert_bytes(s); break;
      default: chance(0.5) ? splice(s, corpus) : duplicate_range(s); break;
    }
  }

  std::mt19937_64 rng_;
  std::vector<std::string> dictionary_;
};

/// Aborts the process (printing what it was doing) when one armed call runs longer than its limit: a hang fails the
/// test run instead of stalling CI until ctest's timeout, and says which input hung.
class Watchdog {
 public:
  Watchdog() : thread_([this] { watch(); }) {}
  ~Watchdog() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
    }
    wake_.notify_all();
    thread_.join();
  }
  Watchdog(const Watchdog&) = delete;
  Watchdog& operator=(const Watchdog&) = delete;

  /// Arms the watchdog for one call of at most `limit` on `input`; if it fires, `label` and the input are printed
  /// and the input is saved as `save_as`.
  void arm(std::chrono::milliseconds limit, std::string label, const std::string& input, std::string save_as) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      armed_ = true;
      deadline_ = std::chrono::steady_clock::now() + limit;
      label_ = std::move(label);
      input_ = input;
      save_as_ = std::move(save_as);
    }
    wake_.notify_all();
  }
  void disarm() {
    std::lock_guard<std::mutex> lock(mutex_);
    armed_ = false;
  }

 private:
  void watch() {
    std::unique_lock<std::mutex> lock(mutex_);
    while (!stop_) {
      if (!armed_) {
        wake_.wait(lock);
        continue;
      }
      const auto deadline = deadline_;
      if (wake_.wait_until(lock, deadline) == std::cv_status::timeout && armed_ && deadline_ == deadline) {
        write_file(save_as_, input_);
        std::fprintf(stderr, "fuzz watchdog: a call ran longer than its limit: %s, input saved as %s:\n%s\n",
                     label_.c_str(), save_as_.c_str(), escaped(input_).c_str());
        std::fflush(stderr);
        std::abort();
      }
    }
  }

  std::mutex mutex_;
  std::condition_variable wake_;
  bool stop_ = false;
  bool armed_ = false;
  std::chrono::steady_clock::time_point deadline_;
  std::string label_;
  std::string input_;
  std::string save_as_;
  std::thread thread_;
};

/// Where a failing input of `target` is saved: under the test temp dir, named by seed and iteration.
inline std::string failure_path(const std::string& target, std::uint64_t seed_value, int iteration,
                                const std::string& extension) {
  return ::testing::TempDir() + "marsala_fuzz_" + target + "_" + std::to_string(seed_value) + "_" +
         std::to_string(iteration) + extension;
}

/// Keeps a failing input: saves it (failure_path) and returns a message naming target, seed, iteration, the file
/// and the input (escaped), to stream into a gtest failure (gtest evaluates it only when the assertion fails).
inline std::string failure_report(const std::string& target, std::uint64_t seed_value, int iteration,
                                  const std::string& input, const std::string& extension) {
  const std::string path = failure_path(target, seed_value, iteration, extension);
  write_file(path, input);
  return target + " seed " + std::to_string(seed_value) + " iteration " + std::to_string(iteration) +
         ", input saved as " + path + ":\n" + escaped(input);
}

}  // namespace marsala::fuzz
