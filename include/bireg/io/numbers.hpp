// bireg io: numbers and timestamps in text, fast and exact.
//
// parse_number reads a finite double with std::from_chars (exactly rounded,
// locale-free, no allocation); the rare tokens it does not take whole (a
// leading '+', hexadecimal floats, out-of-range values) go through strtod so
// that the accepted syntax and the error messages stay those of strtod.
//
// Timestamps keep their text (to be written back exactly) and, when the text
// is a plain decimal (digits, an optional point and exponent) of at most 18
// integer and 18 fractional digits in seconds, an exact fixed-point value:
// differences between such timestamps are exact before their single
// conversion to double, so 1.7e18 ns with 1 ns steps or 1.7e9 s with
// microsecond digits become covariates that keep every digit.
#pragma once

#include <array>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <optional>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include "bireg/io/line_reader.hpp"

namespace bireg {
namespace io {

namespace detail {
struct SeparatorTable {
  bool is[256] = {};
  constexpr SeparatorTable() {
    for (const char c : {',', ' ', '\t', '\r', '\n', '\f', '\v'})
      is[static_cast<unsigned char>(c)] = true;
  }
};
inline constexpr SeparatorTable kSeparators{};
}  // namespace detail

inline bool is_separator(char c) {
  return detail::kSeparators.is[static_cast<unsigned char>(c)];
}

// Splits a line at commas and white space (runs of separators count once).
// `had_comma` tells whether a comma was among the separators.
inline void split_tokens(std::string_view line, std::vector<std::string_view>& tokens,
                         bool* had_comma = nullptr) {
  tokens.clear();
  bool comma = false;
  std::size_t i = 0;
  const std::size_t n = line.size();
  while (i < n) {
    while (i < n && is_separator(line[i])) {
      comma |= line[i] == ',';
      ++i;
    }
    if (i >= n) break;
    std::size_t end = i;
    while (end < n && !is_separator(line[end]))
      ++end;
    tokens.push_back(line.substr(i, end - i));
    i = end;
  }
  if (had_comma) *had_comma = comma;
}

// The most numbers a line of any format holds (the matrix format of a 4 x 4
// group: a time and 16 entries); read_numbers leaves longer lines to
// split_tokens and parse_number.
inline constexpr std::size_t kMaxNumbersPerLine = 17;

// Splits `line` as split_tokens does and reads each token as parse_number
// would, in one pass: from_chars finds where a number ends, so the line is
// scanned once. True when every token is a finite number written the way
// from_chars reads it whole (at most kMaxNumbersPerLine of them: `numbers`
// then holds them); false otherwise, and then `tokens` and `had_comma` are
// split_tokens' and the caller reads the tokens one by one, for the
// messages parse_number gives.
inline bool read_numbers(std::string_view line, std::vector<std::string_view>& tokens,
                         double* numbers, bool& had_comma) {
  std::string_view found[kMaxNumbersPerLine];
  std::size_t count = 0;
  had_comma = false;
  const char* p = line.data();
  const char* const end = p + line.size();
  for (;;) {
    while (p < end && is_separator(*p)) {
      had_comma |= *p == ',';
      ++p;
    }
    if (p == end) break;
    double value = 0;
    const auto result = std::from_chars(p, end, value);
    if (result.ec != std::errc() || (result.ptr != end && !is_separator(*result.ptr)) ||
        !std::isfinite(value) || count == kMaxNumbersPerLine) {
      split_tokens(line, tokens, &had_comma);
      return false;
    }
    numbers[count] = value;
    found[count++] = std::string_view(p, static_cast<std::size_t>(result.ptr - p));
    p = result.ptr;
  }
  tokens.assign(found, found + count);
  return true;
}

// A finite double, or the reason the token is not one: "not a number: '...'",
// "number out of range: '...'" (overflow; underflow reads as 0 or a
// subnormal, as with strtod) or "not a finite number: '...'" (nan, inf).
inline std::optional<std::string> parse_number(std::string_view token, double& value) {
  const char* first = token.data();
  const char* last = first + token.size();
  const auto result = std::from_chars(first, last, value);
  if (result.ec == std::errc() && result.ptr == last) {
    if (std::isfinite(value)) return std::nullopt;
    return "not a finite number: " + quote_excerpt(token);
  }
  // Slow path, rare in real data: strtod decides, on a bounded copy.
  if (token.size() > 400) return "not a number: " + quote_excerpt(token);
  const std::string copy(token);
  errno = 0;
  char* end = nullptr;
  value = std::strtod(copy.c_str(), &end);
  if (copy.empty() || end != copy.c_str() + copy.size()) {
    return "not a number: " + quote_excerpt(token);
  }
  if (errno == ERANGE && std::abs(value) > 1.0) {
    return "number out of range: " + quote_excerpt(token);
  }
  if (!std::isfinite(value)) return "not a finite number: " + quote_excerpt(token);
  return std::nullopt;
}

// The unit of a timestamp column: seconds (TUM, KITTI times, the matrix
// format's covariate) or nanoseconds (EuRoC).
enum class TimeUnit { seconds, nanoseconds };

inline constexpr std::uint64_t kFractionScale = 1000000000000000000ULL;  // 1e18

struct Timestamp {
  std::string text;    // exactly as read
  double seconds = 0;  // the value in seconds, rounded once
  // Exact value in seconds, whole + fraction / 1e18 with fraction in
  // [0, 1e18), when `exact`.
  bool exact = false;
  std::int64_t whole = 0;
  std::uint64_t fraction = 0;
};

namespace detail {

// 10^k for k = 0..18 (10^18 is kFractionScale).
inline constexpr std::array<std::uint64_t, 19> kPowersOf10 = [] {
  std::array<std::uint64_t, 19> powers{};
  powers[0] = 1;
  for (std::size_t k = 1; k < powers.size(); ++k)
    powers[k] = powers[k - 1] * 10;
  return powers;
}();

inline bool exact_decimal_general(std::string_view s, int shift, std::int64_t& whole,
                                  std::uint64_t& fraction);

// The floor form of +-(w + f / 1e18).
inline void set_floor_form(bool negative, std::uint64_t w, std::uint64_t f, std::int64_t& whole,
                           std::uint64_t& fraction) {
  if (!negative || (w == 0 && f == 0)) {
    whole = static_cast<std::int64_t>(w);
    fraction = f;
  } else if (f == 0) {
    whole = -static_cast<std::int64_t>(w);
    fraction = 0;
  } else {
    whole = -static_cast<std::int64_t>(w) - 1;
    fraction = kFractionScale - f;
  }
}

// The exact fixed-point value of a plain decimal token, scaled by 10^-shift
// (shift 9: nanoseconds to seconds). False when the token is not a plain
// decimal or needs more than 18 integer or 18 fractional digits.
//
// The common case in one pass: a sign, at most 19 digits in
// all and an optional point, no exponent. The digits as one integer v
// scaled by 10^-(fraction digits + shift), split at the point.
inline bool exact_decimal(std::string_view s, int shift, std::int64_t& whole,
                          std::uint64_t& fraction) {
  std::size_t i = 0;
  const bool negative = !s.empty() && s[0] == '-';
  if (!s.empty() && (s[0] == '-' || s[0] == '+')) ++i;
  std::uint64_t v = 0;
  int digits = 0, fraction_digits = -1;  // -1: no point yet
  for (; i < s.size(); ++i) {
    const char c = s[i];
    if (c >= '0' && c <= '9') {
      v = v * 10 + static_cast<std::uint64_t>(c - '0');
      ++digits;
      if (fraction_digits >= 0) ++fraction_digits;
    } else if (c == '.' && fraction_digits < 0) {
      fraction_digits = 0;
    } else {
      break;
    }
  }
  const int scale = (fraction_digits < 0 ? 0 : fraction_digits) + shift;
  // 19 digits fit in 64 bits; the whole seconds must stay below 1e18.
  if (i != s.size() || digits == 0 || digits > 19 || scale > 18 ||
      v / kPowersOf10[scale] >= kFractionScale) {
    return exact_decimal_general(s, shift, whole, fraction);
  }
  set_floor_form(negative, v / kPowersOf10[scale],
                 (v % kPowersOf10[scale]) * kPowersOf10[18 - scale], whole, fraction);
  return true;
}

// exact_decimal for any plain decimal, exponent included: the digits one
// by one, each at its decimal position.
inline bool exact_decimal_general(std::string_view s, int shift, std::int64_t& whole,
                                  std::uint64_t& fraction) {
  std::size_t i = 0;
  bool negative = false;
  if (i < s.size() && (s[i] == '+' || s[i] == '-')) negative = s[i++] == '-';
  const std::size_t digits_begin = i;
  std::size_t point = std::string_view::npos, digits_end = i;
  for (; i < s.size(); ++i) {
    if (s[i] == '.' && point == std::string_view::npos) {
      point = i;
    } else if (s[i] < '0' || s[i] > '9') {
      break;
    }
  }
  digits_end = i;
  long exponent = 0;
  if (i < s.size()) {
    if (s[i] != 'e' && s[i] != 'E') return false;
    ++i;
    bool exponent_negative = false;
    if (i < s.size() && (s[i] == '+' || s[i] == '-')) exponent_negative = s[i++] == '-';
    if (i == s.size()) return false;
    for (; i < s.size(); ++i) {
      if (s[i] < '0' || s[i] > '9') return false;
      if (exponent < 100000) exponent = exponent * 10 + (s[i] - '0');
    }
    if (exponent_negative) exponent = -exponent;
  }
  if (point == std::string_view::npos) point = digits_end;
  std::uint64_t w = 0, f = 0;
  bool any_digit = false;
  for (std::size_t k = digits_begin; k < digits_end; ++k) {
    if (k == point) continue;
    any_digit = true;
    const int d = s[k] - '0';
    // Decimal position of this digit in seconds: 0 is the units.
    const long position =
        (k < point ? static_cast<long>(point - k) - 1 : -static_cast<long>(k - point)) + exponent -
        shift;
    if (d == 0) continue;
    if (position >= 18 || position < -18) return false;
    if (position >= 0) {
      w += static_cast<std::uint64_t>(d) * kPowersOf10[position];
    } else {
      f += static_cast<std::uint64_t>(d) * kPowersOf10[18 + position];
    }
  }
  if (!any_digit) return false;
  // |value| < 1e18: w fits in int64; floor form for negative values.
  set_floor_form(negative, w, f, whole, fraction);
  return true;
}

}  // namespace detail

// The timestamp of a token that parse_number has read as `value`.
inline void timestamp_of_number(std::string_view token, double value, TimeUnit unit,
                                Timestamp& out) {
  const int shift = unit == TimeUnit::nanoseconds ? 9 : 0;
  out.text.assign(token.data(), token.size());
  out.seconds = unit == TimeUnit::nanoseconds ? value * 1e-9 : value;
  out.exact = detail::exact_decimal(token, shift, out.whole, out.fraction);
}

// Reads a timestamp token in `unit`: a finite number (parse_number's rules
// and messages), kept as text and, when possible, exactly.
inline std::optional<std::string> parse_timestamp(std::string_view token, TimeUnit unit,
                                                  Timestamp& out) {
  double value = 0;
  if (auto problem = parse_number(token, value)) return problem;
  timestamp_of_number(token, value, unit, out);
  return std::nullopt;
}

// A timestamp made from a frame index (KITTI without a times file).
inline Timestamp frame_timestamp(std::uint64_t index) {
  Timestamp t;
  t.text = std::to_string(index);
  t.seconds = static_cast<double>(index);
  t.exact = index < 1000000000000000000ULL;
  t.whole = static_cast<std::int64_t>(index);
  return t;
}

// a < b, exactly when both are exact.
inline bool earlier(const Timestamp& a, const Timestamp& b) {
  if (a.exact && b.exact) {
    return a.whole < b.whole || (a.whole == b.whole && a.fraction < b.fraction);
  }
  return a.seconds < b.seconds;
}

// t - origin in seconds: exact difference, one rounding to double (through
// long double where it is wider), when both are exact.
inline double seconds_between(const Timestamp& t, const Timestamp& origin) {
  if (t.exact && origin.exact) {
    const auto whole = static_cast<long double>(t.whole - origin.whole);
    const long double fraction =
        (static_cast<long double>(t.fraction) - static_cast<long double>(origin.fraction)) /
        static_cast<long double>(kFractionScale);
    return static_cast<double>(whole + fraction);
  }
  return t.seconds - origin.seconds;
}

// The timestamp's value written in `unit`: exact decimal digits when the
// value is exact (no exponent, trailing zeros of the fraction dropped),
// otherwise the shortest text that reads back to the rounded value.
inline std::string render_timestamp(const Timestamp& t, TimeUnit unit) {
  const auto shortest = [](double x) {
    char buffer[32];
    const auto result = std::to_chars(buffer, buffer + sizeof buffer, x);
    return std::string(buffer, result.ptr);
  };
  if (!t.exact) return shortest(unit == TimeUnit::nanoseconds ? t.seconds * 1e9 : t.seconds);
  // Magnitude and sign from the floor form.
  const bool negative = t.whole < 0;
  std::uint64_t w = 0, f = 0;
  if (!negative) {
    w = static_cast<std::uint64_t>(t.whole);
    f = t.fraction;
  } else if (t.fraction == 0) {
    w = static_cast<std::uint64_t>(-(t.whole + 1)) + 1;
  } else {
    w = static_cast<std::uint64_t>(-(t.whole + 1));
    f = kFractionScale - t.fraction;
  }
  if (unit == TimeUnit::nanoseconds) {
    if (w >= 9000000000ULL) return shortest(t.seconds * 1e9);
    w = w * 1000000000ULL + f / 1000000000ULL;
    f = (f % 1000000000ULL) * 1000000000ULL;
  }
  std::string s = negative ? "-" : "";
  s += std::to_string(w);
  if (f != 0) {
    std::string digits = std::to_string(f);
    digits.insert(0, 18 - digits.size(), '0');
    while (!digits.empty() && digits.back() == '0')
      digits.pop_back();
    s += "." + digits;
  }
  return s;
}

}  // namespace io
}  // namespace bireg
