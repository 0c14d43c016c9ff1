// The io/ layer on its own: the line reader's bounds and errors, numbers and
// exact timestamps, every format read, written and read again, detection,
// projection, column counts and write errors.
#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <random>
#include <sstream>
#include <stdexcept>
#include <streambuf>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "bireg/groups/matrix_group.hpp"
#include "bireg/groups/se2.hpp"
#include "bireg/groups/se3.hpp"
#include "bireg/groups/sim3.hpp"
#include "bireg/groups/so3.hpp"
#include "bireg/io/formats.hpp"
#include "bireg/io/line_reader.hpp"
#include "bireg/io/numbers.hpp"
#include "bireg/io/writers.hpp"
#include "catch.hpp"
#include "test_support.hpp"

namespace {

using bireg::io::Format;
using SE3 = bireg::SE3<double>;
using SO3 = bireg::SO3<double>;

std::vector<std::string> all_lines(bireg::io::ByteSource& source, std::size_t max_line,
                                   std::optional<bireg::io::ParseError>& error,
                                   std::size_t block = 7) {
  bireg::io::LineReader reader(source, max_line, block);
  std::vector<std::string> lines;
  std::string_view line;
  while (reader.next(line))
    lines.emplace_back(line);
  error = reader.error();
  return lines;
}

template <class G>
std::optional<bireg::io::ParseError> read_text(const std::string& text,
                                               const bireg::io::ReadOptions& options,
                                               bireg::io::Trajectory<G>& out) {
  bireg::io::MemorySource source(text);
  return bireg::io::read_trajectory<G>(source, options, out);
}

template <class G>
bireg::io::Trajectory<G> read_ok(const std::string& text, bireg::io::ReadOptions options = {}) {
  bireg::io::Trajectory<G> trajectory;
  const auto error = read_text<G>(text, options, trajectory);
  CAPTURE(text.substr(0, 300), error ? error->message : std::string());
  REQUIRE_FALSE(error.has_value());
  return trajectory;
}

template <class G>
bireg::io::ParseError read_error(const std::string& text, bireg::io::ReadOptions options = {}) {
  bireg::io::Trajectory<G> trajectory;
  const auto error = read_text<G>(text, options, trajectory);
  CAPTURE(text.substr(0, 300));
  REQUIRE(error.has_value());
  return *error;
}

// A random SE(3) trajectory with `n` poses.
std::vector<SE3::Element> random_poses(std::size_t n, unsigned seed) {
  std::mt19937 rng(seed);
  std::vector<SE3::Element> poses;
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Matrix<double, 6, 1> x =
        bireg_test::random_tangent<Eigen::Matrix<double, 6, 1>>(rng, 2.0);
    poses.push_back(SE3::exp(x));
  }
  return poses;
}

std::vector<bireg::io::Timestamp> timestamps_of(const std::vector<std::string>& texts,
                                                bireg::io::TimeUnit unit) {
  std::vector<bireg::io::Timestamp> out;
  for (const auto& text : texts) {
    bireg::io::Timestamp t;
    REQUIRE_FALSE(bireg::io::parse_timestamp(text, unit, t).has_value());
    out.push_back(t);
  }
  return out;
}

}  // namespace

TEST_CASE("line reader: ends of line, bounded length, NUL bytes, 64-bit counts", "[io]") {
  std::optional<bireg::io::ParseError> error;
  {
    bireg::io::MemorySource source("a\r\nbb\n\nccc");
    const auto lines = all_lines(source, 100, error);
    REQUIRE_FALSE(error);
    REQUIRE(lines == std::vector<std::string>{"a", "bb", "", "ccc"});
  }
  {
    // A line of exactly the limit passes, one byte more is an error naming it.
    const std::string ok(16, 'x');
    const std::string text = "1\n" + ok + "\n" + ok + "y\n4\n";
    bireg::io::MemorySource source(text);
    const auto lines = all_lines(source, 16, error);
    REQUIRE(lines.size() == 2);
    REQUIRE(error);
    REQUIRE(error->line == 3);
    REQUIRE(error->message == "line longer than 16 bytes (the limit)");
  }
  {
    // The last line, without '\n', is bounded too.
    const std::string text = "1\n" + std::string(40, 'z');
    bireg::io::MemorySource source(text);
    all_lines(source, 16, error);
    REQUIRE(error);
    REQUIRE(error->line == 2);
  }
  {
    const std::string text = std::string("1 2\n3 4\n5") + '\0' + "6\n";
    bireg::io::MemorySource source(text);
    const auto lines = all_lines(source, 100, error);
    REQUIRE(lines.size() == 2);
    REQUIRE(error);
    REQUIRE(error->line == 3);
    REQUIRE(error->message.find("NUL") != std::string::npos);
  }
  STATIC_REQUIRE(std::is_same_v<decltype(error->line), std::uint64_t>);
  STATIC_REQUIRE(
      std::is_same_v<
          decltype(bireg::io::LineReader(std::declval<bireg::io::ByteSource&>()).line_number()),
          std::uint64_t>);
}

// A file whose last line has no '\n' (common from editors and scripts):
// that line is counted like the others, both in an error and in the source
// line recorded for each observation.
TEST_CASE("the last line without a newline has its own line number", "[io]") {
  REQUIRE(read_error<SO3>("0 1 0 0 0 1 0 0 0 1\n1 1 0 0 0 1 0 0 0 x").line == 2);
  const auto ok = read_ok<SO3>("# header\n0 1 0 0 0 1 0 0 0 1\n1 1 0 0 0 1 0 0 0 1");
  REQUIRE(ok.lines == std::vector<std::uint64_t>{2, 3});
}

TEST_CASE("line reader: /dev/zero fails at once on line 1 with bounded memory", "[io]") {
  std::FILE* zero = std::fopen("/dev/zero", "rb");
  if (!zero) {
    WARN("no /dev/zero: skipped");
    return;
  }
  bireg::io::FileSource source(zero);
  std::optional<bireg::io::ParseError> error;
  const auto lines = all_lines(source, bireg::io::kMaxLineLength, error, std::size_t{1} << 16);
  std::fclose(zero);
  REQUIRE(lines.empty());
  REQUIRE(error);
  REQUIRE(error->line == 1);
  REQUIRE(error->message.find("NUL") != std::string::npos);
}

namespace {
// A stream whose buffer fails after some bytes, as a disk read error would.
class FailingBuffer : public std::streambuf {
 public:
  explicit FailingBuffer(std::string text) : text_(std::move(text)) {
    setg(text_.data(), text_.data(), text_.data() + text_.size());
  }

 protected:
  int_type underflow() override { throw std::runtime_error("I/O error"); }

 private:
  std::string text_;
};
}  // namespace

TEST_CASE("a read error is an error, not the end of the input", "[io]") {
  const std::string first = "0 0 0 0 0 0 0 1\n1 0 0 0 0 0 0 1\n";
  FailingBuffer buffer(first);
  std::istream in(&buffer);
  bireg::io::Trajectory<SE3> trajectory;
  const auto error = bireg::io::read_trajectory<SE3>(in, Format::tum, trajectory);
  REQUIRE(error);
  REQUIRE(error->message.find("read error") != std::string::npos);

  // A directory opened as a file fails on its first read.
  std::FILE* directory = std::fopen("/", "rb");
  if (directory) {
    bireg::io::FileSource source(directory);
    bireg::io::ReadOptions options;
    const auto e = bireg::io::read_trajectory<SE3>(source, options, trajectory);
    std::fclose(directory);
    REQUIRE(e);
    REQUIRE(e->message.find("read error") != std::string::npos);
  }
}

TEST_CASE("error excerpts are bounded and escaped", "[io]") {
  REQUIRE(bireg::io::quote_excerpt("abc") == "'abc'");
  const std::string hostile = "\x1b[2J\x1b]0;pwned\x07" + std::string(1000, 'A');
  const std::string quoted = bireg::io::quote_excerpt(hostile);
  REQUIRE(quoted.size() <= 40 * 4 + 5);
  for (char c : quoted)
    REQUIRE((c >= 0x20 && c < 0x7f));
  REQUIRE(quoted.find("...") != std::string::npos);
  const auto e = read_error<SO3>("0 1 0 0 0 1 0 0 0 " + hostile + "\n");
  for (char c : e.message)
    REQUIRE((c >= 0x20 && c < 0x7f));
  REQUIRE(e.message.size() < 200);
}

TEST_CASE("numbers: from_chars fast path, strtod's syntax and messages kept", "[io]") {
  double x = 0;
  REQUIRE_FALSE(bireg::io::parse_number("0.1", x));
  REQUIRE(x == 0.1);
  REQUIRE_FALSE(bireg::io::parse_number("+2.5e-3", x));
  REQUIRE(x == 2.5e-3);
  REQUIRE_FALSE(bireg::io::parse_number("1e-400", x));  // underflow reads as 0
  REQUIRE(x == 0);
  REQUIRE(*bireg::io::parse_number("1e400", x) == "number out of range: '1e400'");
  REQUIRE(*bireg::io::parse_number("nan", x) == "not a finite number: 'nan'");
  REQUIRE(*bireg::io::parse_number("-inf", x) == "not a finite number: '-inf'");
  REQUIRE(*bireg::io::parse_number("abc", x) == "not a number: 'abc'");
  REQUIRE(*bireg::io::parse_number("1.5x", x) == "not a number: '1.5x'");
  // Every double survives format_double and parse_number.
  std::mt19937_64 rng(7);
  for (int i = 0; i < 10000; ++i) {
    double y = 0;
    const std::uint64_t bits = rng();
    std::memcpy(&y, &bits, sizeof y);
    if (!std::isfinite(y)) continue;
    double back = 0;
    REQUIRE_FALSE(bireg::io::parse_number(bireg::io::format_double(y), back));
    REQUIRE(back == y);
  }
}

TEST_CASE("read_numbers: one pass gives split_tokens' tokens and parse_number's values", "[io]") {
  // Lines of tokens that from_chars reads whole, and of tokens it does not
  // (strtod's syntax, non-finite values, words, glued garbage), joined by
  // runs of every separator.
  const std::vector<std::string> pool = {"0",
                                         "-1.5",
                                         "2.5e-3",
                                         "1700000000.000001",
                                         "-0.5595888894234176",
                                         "1e-400",
                                         ".5",
                                         "5.",
                                         "+2",
                                         "1e400",
                                         "nan",
                                         "-inf",
                                         "abc",
                                         "1.5x",
                                         "0x1p3",
                                         "1e",
                                         "--1",
                                         "1,5",
                                         "1700000000000000003"};
  const std::vector<std::string> separators = {" ", ",", "\t", " , ", "  ", "\r", "\f\v"};
  std::mt19937 rng(11);
  double numbers[bireg::io::kMaxNumbersPerLine];
  for (int trial = 0; trial < 20000; ++trial) {
    std::string line;
    const int count = static_cast<int>(rng() % 20);
    if (rng() % 3 == 0) line += separators[rng() % separators.size()];
    for (int k = 0; k < count; ++k) {
      // Mostly clean numbers, as in real files.
      line += pool[rng() % (rng() % 4 == 0 ? pool.size() : 8)];
      if (k + 1 < count || rng() % 3 == 0) line += separators[rng() % separators.size()];
    }
    std::vector<std::string_view> tokens, expected;
    bool had_comma = false, expected_comma = false;
    const bool all = bireg::io::read_numbers(line, tokens, numbers, had_comma);
    bireg::io::split_tokens(line, expected, &expected_comma);
    CAPTURE(line);
    // As strings: Catch prints a std::string_view only where its own
    // library was built with C++17 string_view support.
    REQUIRE(std::vector<std::string>(tokens.begin(), tokens.end()) ==
            std::vector<std::string>(expected.begin(), expected.end()));
    REQUIRE(had_comma == expected_comma);
    // True exactly when from_chars reads every token whole as a finite
    // number (strtod's extra syntax, '+2' or hexadecimal, and underflow are
    // left to parse_number); then the values are parse_number's.
    bool every_token_reads = expected.size() <= bireg::io::kMaxNumbersPerLine;
    for (std::size_t k = 0; k < expected.size(); ++k) {
      const char* first = expected[k].data();
      const char* last = first + expected[k].size();
      double direct = 0;
      const auto result = std::from_chars(first, last, direct);
      every_token_reads = every_token_reads && result.ec == std::errc() && result.ptr == last &&
                          std::isfinite(direct);
      double value = 0;
      if (all) {
        REQUIRE_FALSE(bireg::io::parse_number(expected[k], value));
        REQUIRE(numbers[k] == value);
      }
    }
    REQUIRE(all == every_token_reads);
  }
}

TEST_CASE("exact decimals: the one-pass reader agrees with the general one", "[io]") {
  // Signs, 0-21 integer and fraction digits (leading and trailing zeros
  // included), with or without a point, sometimes an exponent, in seconds
  // and nanoseconds: both readers give the same answer, exact or not.
  std::mt19937 rng(5);
  const auto digits = [&](int n) {
    std::string s;
    for (int k = 0; k < n; ++k)
      s += static_cast<char>('0' + (rng() % 3 == 0 ? 0 : rng() % 10));
    return s;
  };
  int fast = 0;
  for (int trial = 0; trial < 200000; ++trial) {
    std::string token;
    const unsigned sign = rng() % 4;
    if (sign == 1) token += '-';
    if (sign == 2) token += '+';
    token += digits(static_cast<int>(rng() % 22));
    if (rng() % 2) token += "." + digits(static_cast<int>(rng() % 22));
    if (rng() % 10 == 0) token += "e" + std::to_string(static_cast<int>(rng() % 41) - 20);
    const int shift = rng() % 2 ? 9 : 0;
    std::int64_t whole = 7, general_whole = 7;
    std::uint64_t fraction = 3, general_fraction = 3;
    const bool exact = bireg::io::detail::exact_decimal(token, shift, whole, fraction);
    const bool general =
        bireg::io::detail::exact_decimal_general(token, shift, general_whole, general_fraction);
    CAPTURE(token, shift);
    REQUIRE(exact == general);
    if (exact) {
      REQUIRE(whole == general_whole);
      REQUIRE(fraction == general_fraction);
      fast += token.find('e') == std::string::npos;
    }
  }
  REQUIRE(fast > 10000);  // the one-pass path was exercised
}

TEST_CASE("the reader reserves for the lines left once, from any source", "[io]") {
  // 5,000 lines of one length (245 KB, more than the reader's 64 KiB
  // block, so the source's size hint decides): with the estimate the
  // vectors hold 5,000 to 5,000 * 1.125 + 2; from the buffered block alone
  // (no hint) they would double past it, to about 6,000.
  constexpr int kLines = 5000;
  std::string text;
  for (int i = 0; i < kLines; ++i) {
    char line[96];
    std::snprintf(line, sizeof line, "%d.%06d 0.%06d 1.5 -2.%06d 0 0 0 1\n", 1700000000 + i,
                  (37 * i) % 1000000, (91 * i) % 1000000, (53 * i) % 1000000);
    text += line;
  }
  const std::size_t most = kLines + kLines / 8 + 2;
  const auto memory = read_ok<SE3>(text);
  REQUIRE(memory.observations.size() == kLines);
  REQUIRE(memory.observations.capacity() <= most);
  REQUIRE(memory.timestamps.capacity() == memory.observations.capacity());

  // A regular file (fstat's size) reads the same with the same reservation;
  // a stream (no hint) reads the same.
  std::FILE* file = std::tmpfile();
  REQUIRE(file != nullptr);
  REQUIRE(std::fwrite(text.data(), 1, text.size(), file) == text.size());
  std::rewind(file);
  bireg::io::FileSource file_source(file);
  REQUIRE(file_source.size_hint() == text.size());
  bireg::io::Trajectory<SE3> from_file, from_stream;
  REQUIRE_FALSE(bireg::io::read_trajectory<SE3>(file_source, bireg::io::ReadOptions{}, from_file));
  std::fclose(file);
  REQUIRE(from_file.observations.capacity() <= most);
  std::istringstream stream(text);
  REQUIRE_FALSE(bireg::io::read_trajectory<SE3>(stream, bireg::io::ReadOptions{}, from_stream));
  REQUIRE(from_stream.observations.capacity() > most);
  REQUIRE(from_file.observations == memory.observations);
  REQUIRE(from_stream.observations == memory.observations);
  REQUIRE(from_file.covariates == memory.covariates);
  REQUIRE(from_stream.covariates == memory.covariates);

  // A first line much shorter than the rest makes the estimate long: it is
  // bounded, and the result is the same.
  const std::string uneven = "1 0 0 0 0 0 0 1\n" + text;
  const auto grown = read_ok<SE3>(uneven);
  REQUIRE(grown.observations.size() == kLines + 1);
  REQUIRE(std::equal(memory.observations.begin(), memory.observations.end(),
                     grown.observations.begin() + 1));
  using bireg::io::detail::reservation;
  REQUIRE(reservation(std::size_t{1} << 40, 16) == bireg::io::detail::kMaxReservedLines);
  REQUIRE(reservation(std::numeric_limits<std::size_t>::max(), 1) ==
          bireg::io::detail::kMaxReservedLines);
  REQUIRE(reservation(0, 50) == 1);
  REQUIRE(reservation(49000, 49) == 1001 + 1001 / 8);
}

TEST_CASE("a quaternion's rotation is taken as a rotation, whatever element_tolerance", "[io]") {
  // Normalised, a quaternion gives an orthonormal matrix to rounding; the
  // reader does not ask is_element, so a zero tolerance still reads it.
  bireg::io::ReadOptions options;
  options.element_tolerance = 0;
  const auto tum =
      read_ok<SE3>("0 1 2 3 0.1 0.2 0.3 0.927362\n1 1 2 3 0.3 -0.2 0.6 0.714143\n", options);
  REQUIRE(tum.observations.size() == 2);
  for (const auto& g : tum.observations) {
    const Eigen::Matrix3d r = g.topLeftCorner<3, 3>();
    REQUIRE((r.transpose() * r - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() < 1e-15);
    REQUIRE(r.determinant() == Approx(1).margin(1e-15));
  }
  // A matrix line is still checked, and a tolerance that is not a
  // non-negative number is refused.
  const auto error = read_error<SE3>("0 1 0 0 0 0 1 0 0 0 0 1.001 0 0 0 0 1\n");
  REQUIRE(error.message.find("not an element of SE3") != std::string::npos);
  for (const double tolerance : {-1.0, std::nan("")}) {
    options.element_tolerance = tolerance;
    const auto refused = read_error<SE3>("0 1 2 3 0 0 0 1\n", options);
    REQUIRE(refused.line == 0);
    REQUIRE(refused.message == "element_tolerance must be a non-negative number");
  }
}

TEST_CASE("a quaternion whose squares overflow is normalised, not turned into the identity",
          "[io]") {
  // (x, y, z, w) = (1e200, 1e200, 0, 0): the half turn about (1, 1, 0).
  bireg::io::ReadOptions project;
  project.project = true;
  const auto tum = read_ok<SE3>("0 1 2 3 1e200 1e200 0 0\n1 1 2 3 0 0 0 1\n", project);
  Eigen::Matrix3d half_turn;
  half_turn << 0, 1, 0, 1, 0, 0, 0, 0, -1;
  REQUIRE((tum.observations[0].topLeftCorner<3, 3>() - half_turn).cwiseAbs().maxCoeff() < 1e-15);
  REQUIRE(std::isfinite(tum.projection_correction));
  REQUIRE(tum.projection_correction == Approx(std::sqrt(2.0) * 1e200));
  // Without --project such a norm is far from 1, and says so.
  const auto error = read_error<SE3>("0 1 2 3 1e200 1e200 0 0\n");
  REQUIRE(error.message == "quaternion norm 1.41421e+200 is far from 1 (--project normalises it)");
  // Components near the largest double: the norm overflows even when
  // scaled, and the quaternion is refused rather than made the identity.
  for (const auto& options : {project, bireg::io::ReadOptions{}}) {
    const auto beyond = read_error<SE3>("0 1 2 3 1.5e308 1.5e308 0 0\n", options);
    REQUIRE(beyond.line == 1);
    REQUIRE(beyond.message == "quaternion norm beyond the range of double");
  }
}

TEST_CASE("timestamps: exact differences at 1.7e18 ns and 1.7e9 s", "[io]") {
  using bireg::io::TimeUnit;
  // 1 ns apart at 1.7e18 ns: every covariate distinct, exactly 1e-9 s apart.
  std::string text = "#timestamp [ns],x,y,z,qw,qx,qy,qz\n";
  for (int i = 0; i < 5; ++i)
    text += std::to_string(1700000000000000000LL + i) + "," + std::to_string(i) + ",0,0,1,0,0,0\n";
  const auto euroc = read_ok<SE3>(text);
  REQUIRE(euroc.format == Format::euroc);
  const std::vector<double> expected = {0, 1e-9, 2e-9, 3e-9, 4e-9};
  REQUIRE(euroc.covariates == expected);
  for (int i = 0; i < 5; ++i) {
    REQUIRE(euroc.timestamps[i].text == std::to_string(1700000000000000000LL + i));
  }
  REQUIRE(bireg::io::render_timestamp(euroc.timestamps[3], TimeUnit::seconds) ==
          "1700000000.000000003");
  REQUIRE(bireg::io::render_timestamp(euroc.timestamps[3], TimeUnit::nanoseconds) ==
          "1700000000000000003");

  // TUM seconds with microsecond digits; the earliest line need not be first.
  const auto tum = read_ok<SE3>(
      "1700000000.000003 0 0 0 0 0 0 1\n1700000000.000001 0 0 0 0 0 0 1\n"
      "1700000000.000002 1 0 0 0 0 0 1\n");
  REQUIRE(tum.origin.text == "1700000000.000001");
  REQUIRE(tum.covariates == std::vector<double>{2e-6, 0, 1e-6});
  REQUIRE(bireg::io::render_timestamp(tum.timestamps[0], TimeUnit::nanoseconds) ==
          "1700000000000003000");

  // Exponents, signs and values beyond 18 digits.
  const auto t = timestamps_of({"1.036594e-01", "-2.5", "-0.000001", "12345678901234567890"},
                               TimeUnit::seconds);
  REQUIRE(t[0].exact);
  REQUIRE(bireg::io::render_timestamp(t[0], TimeUnit::seconds) == "0.1036594");
  REQUIRE(bireg::io::render_timestamp(t[1], TimeUnit::seconds) == "-2.5");
  REQUIRE(bireg::io::render_timestamp(t[2], TimeUnit::nanoseconds) == "-1000");
  REQUIRE(bireg::io::seconds_between(t[0], t[1]) == 2.6036594);
  REQUIRE_FALSE(t[3].exact);
  REQUIRE(t[3].seconds == 12345678901234567890.0);
}

namespace {

// The same poses written in `format`, with timestamps in its unit.
std::string write_as(Format format, const std::vector<std::string>& seconds,
                     const std::vector<std::string>& nanoseconds,
                     const std::vector<SE3::Element>& poses) {
  const auto& texts = format == Format::euroc ? nanoseconds : seconds;
  return bireg::io::format_trajectory<SE3>(
      format, format, timestamps_of(texts, bireg::io::time_unit(format)), poses);
}

}  // namespace

TEST_CASE("round trip: every format read, written, read again", "[io]") {
  const auto poses = random_poses(25, 3);
  std::vector<std::string> seconds, nanoseconds;
  for (int i = 0; i < 25; ++i) {
    seconds.push_back("1700000000." + std::to_string(100000 + 37 * i));
    nanoseconds.push_back(std::to_string(1700000000100000000LL + 37000LL * i));
  }
  for (Format format : {Format::matrix, Format::tum, Format::euroc, Format::kitti}) {
    CAPTURE(bireg::io::to_string(format));
    bireg::io::ReadOptions options;
    options.format = format;
    const auto times = timestamps_of(seconds, bireg::io::TimeUnit::seconds);
    options.times = &times;
    const auto first = read_ok<SE3>(write_as(format, seconds, nanoseconds, poses), options);
    const std::string written =
        bireg::io::format_trajectory<SE3>(format, format, first.timestamps, first.observations);
    const auto second = read_ok<SE3>(written, options);
    REQUIRE(second.observations.size() == poses.size());
    for (std::size_t i = 0; i < poses.size(); ++i) {
      // Matrices print exactly; quaternions go through a rotation matrix and
      // back: a few ulps.
      REQUIRE(bireg_test::relative_error(second.observations[i], poses[i]) <= 1e-14);
      if (format == Format::matrix || format == Format::kitti) {
        REQUIRE(second.observations[i] == first.observations[i]);
      }
      REQUIRE(second.timestamps[i].text == first.timestamps[i].text);
      REQUIRE(second.covariates[i] == first.covariates[i]);
    }
    // Auto-detection reads the written text as the same format.
    bireg::io::ReadOptions detect;
    detect.times = &times;
    REQUIRE(read_ok<SE3>(written, detect).format == format);
    // SO3 reads the rotations of every pose format.
    if (format != Format::matrix) {
      const auto rotations = read_ok<SO3>(written, options);
      for (std::size_t i = 0; i < poses.size(); ++i) {
        const SO3::Element r = poses[i].topLeftCorner<3, 3>();
        REQUIRE(bireg_test::relative_error(rotations.observations[i], r) <= 1e-14);
      }
    }
  }
  // Conversion between units is exact: TUM seconds to EuRoC nanoseconds and
  // back gives the same value (the same text, trailing zeros aside).
  const auto tum = read_ok<SE3>(write_as(Format::tum, seconds, nanoseconds, poses));
  const std::string euroc =
      bireg::io::format_trajectory<SE3>(Format::euroc, Format::tum, tum.timestamps, poses);
  const auto back = read_ok<SE3>(euroc);
  REQUIRE(back.format == Format::euroc);
  for (std::size_t i = 0; i < poses.size(); ++i) {
    REQUIRE(back.timestamps[i].text == nanoseconds[i]);
    REQUIRE(bireg::io::timestamp_text(back.timestamps[i], Format::euroc, Format::tum) ==
            bireg::io::render_timestamp(tum.timestamps[i], bireg::io::TimeUnit::seconds));
    REQUIRE(back.covariates[i] == tum.covariates[i]);
  }
}

TEST_CASE("column counts: extra and missing columns are errors where the format fixes them",
          "[io]") {
  bireg::io::ReadOptions options;
  const std::string so3 = "1, 1, 0, 0, 0, 1, 0, 0, 0, 1";
  options.format = Format::matrix;
  REQUIRE(read_error<SO3>(so3 + ", 0\n", options).message == "expected 10 numbers, found 11");
  REQUIRE(read_error<SO3>("1, 1, 0, 0, 0, 1, 0, 0, 0\n", options).message ==
          "expected 10 numbers, found 9");
  options.format = Format::tum;
  REQUIRE(read_error<SE3>("0 0 0 0 0 0 0 1 0\n", options).message ==
          "expected 8 numbers (timestamp tx ty tz qx qy qz qw), found 9");
  REQUIRE(read_error<SE3>("0 0 0 0 0 0 1\n", options).message ==
          "expected 8 numbers (timestamp tx ty tz qx qy qz qw), found 7");
  options.format = Format::kitti;
  REQUIRE(read_error<SE3>("1 0 0 0 0 1 0 0 0 0 1 0 5\n", options).message ==
          "expected 12 numbers (a 3x4 pose, row-major), found 13");
  options.format = Format::euroc;
  REQUIRE(read_error<SE3>("0,0,0,0,1,0,0\n", options).message ==
          "expected at least 8 numbers (timestamp p_x p_y p_z q_w q_x q_y q_z), found 7");
  // EuRoC ignores the columns after the eighth, unread.
  const auto extra = read_ok<SE3>("0,0,0,0,1,0,0,0,v,w\n5,0,0,0,1,0,0,0,,\n", options);
  REQUIRE(extra.observations.size() == 2);
  REQUIRE(extra.covariates[1] == 5e-9);
}

TEST_CASE("format detection by content, ambiguity named", "[io]") {
  REQUIRE(read_ok<SE3>("0 0 0 0 0 0 0 1\n").format == Format::tum);
  REQUIRE(read_ok<SE3>("1 0 0 0 0 1 0 0 0 0 1 0\n").format == Format::kitti);
  REQUIRE(read_ok<SO3>("0, 1, 0, 0, 0, 1, 0, 0, 0, 1\n").format == Format::matrix);
  REQUIRE(read_ok<SE3>("# timestamp\n0,0,0,0,1,0,0,0\n").format == Format::euroc);
  // Without the header, a comma-separated 8-column line is no format.
  REQUIRE(read_error<SE3>("0,0,0,0,1,0,0,0\n").message.find("no format fits") == 0);
  // A header mentioning timestamps and a 10-column SO3 line valid both as a
  // matrix and as EuRoC (identity rotation, unit quaternion (0, 1, 0, 0)).
  const auto ambiguous = read_error<SO3>("#timestamp\n0, 1, 0, 0, 0, 1, 0, 0, 0, 1\n");
  REQUIRE(ambiguous.line == 2);
  REQUIRE(ambiguous.message.find("ambiguous format") == 0);
  REQUIRE(ambiguous.message.find("matrix or euroc") != std::string::npos);
  // The same line as a rotation that is not EuRoC-valid: matrix.
  REQUIRE(read_ok<SO3>("#timestamp\n0, 0, 0, 1, 0, 1, 0, -1, 0, 0\n").format == Format::matrix);
  // Other groups read the matrix format without detection.
  REQUIRE(read_ok<bireg::SE2<double>>("0 1 0 0 0 1 0 0 0 1\n").format == Format::matrix);
}

TEST_CASE(
    "projection (--project): quaternions normalised, rotation blocks projected, degenerate refused",
    "[io]") {
  bireg::io::ReadOptions strict, project;
  project.project = true;
  const std::string tum = "0 0 0 0 0 0 0 1.01\n1 1 0 0 0 0 0 1\n";
  REQUIRE(read_error<SE3>(tum, strict).message.find("quaternion norm 1.01 is far from 1") == 0);
  const auto projected = read_ok<SE3>(tum, project);
  REQUIRE(std::abs(projected.projection_correction - 0.01) < 1e-12);
  REQUIRE(SE3::is_element(projected.observations[0], 1e-14));
  REQUIRE(read_error<SE3>("0 0 0 0 0 0 0 0\n", project).message.find("too small") !=
          std::string::npos);

  const std::string kitti = "1.001 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 1 0 1 0 0 0 0 1 0\n";
  REQUIRE(read_error<SE3>(kitti, strict).message.find("not an element of SE3") !=
          std::string::npos);
  const auto k = read_ok<SE3>(kitti, project);
  REQUIRE(std::abs(k.projection_correction - 0.001) < 1e-12);
  REQUIRE(k.observations[0].isIdentity(1e-14));
  REQUIRE(read_error<SE3>("1 0 0 0 0 0 0 0 0 0 0 0\n", project).message.find("rank < 2") !=
          std::string::npos);
  // Matrix format, SO3: a rotation off by 1e-4 in one entry.
  const std::string matrix = "0, 1, 1e-4, 0, 0, 1, 0, 0, 0, 1\n";
  REQUIRE(read_error<SO3>(matrix, strict).message.find("--project") != std::string::npos);
  const auto m = read_ok<SO3>(matrix, project);
  REQUIRE(m.projection_correction > 0);
  REQUIRE(m.projection_correction < 1e-4);
  REQUIRE(SO3::is_element(m.observations[0], 1e-14));
  REQUIRE(read_error<bireg::SL3<double>>("0 1 0 0 0 1 0 0 0 1\n", project)
              .message.find("--project applies") == 0);
}

TEST_CASE("KITTI times: one per pose, counted", "[io]") {
  bireg::io::MemorySource times_text("# times\n0.0\n1.036594e-01\n2.073188e-01\n");
  std::vector<bireg::io::Timestamp> times;
  REQUIRE_FALSE(bireg::io::read_times(times_text, times));
  REQUIRE(times.size() == 3);
  bireg::io::ReadOptions options;
  options.times = &times;
  const std::string pose = "1 0 0 0 0 1 0 0 0 0 1 0\n";
  const auto k = read_ok<SE3>(pose + pose + pose, options);
  REQUIRE(k.covariates[2] == 0.2073188);
  REQUIRE(read_error<SE3>(pose + pose, options).message == "3 times for 2 poses");
  REQUIRE(read_error<SE3>(pose + pose + pose + pose, options).line == 4);
  REQUIRE(read_ok<SE3>(pose + pose).covariates == std::vector<double>{0, 1});
  bireg::io::MemorySource bad("0\n1 2\n");
  const auto e = bireg::io::read_times(bad, times);
  REQUIRE(e);
  REQUIRE(e->line == 2);
}

TEST_CASE("write errors are reported", "[io]") {
  std::FILE* full = std::fopen("/dev/full", "wb");
  if (!full) {
    WARN("no /dev/full: skipped");
    return;
  }
  const auto poses = random_poses(3, 1);
  const auto times = timestamps_of({"0", "1", "2"}, bireg::io::TimeUnit::seconds);
  const auto error = bireg::io::write_trajectory<SE3>(full, Format::tum, Format::tum, times, poses);
  std::fclose(full);
  REQUIRE(error);
  REQUIRE(error->find("write error") == 0);
}

// Sim(3) reads the pose formats (a rigid pose is a similarity of scale 1;
// bireg_fit --group auto relies on it) and detects them by content like
// SE(3); writing a similarity in a pose format is refused, never a silent
// drop of the scale.
TEST_CASE("Sim3 reads the pose formats as scale 1 and refuses to write them", "[io]") {
  using Sim3 = bireg::Sim3<double>;
  const auto poses = random_poses(4, 2);
  const auto times = timestamps_of({"0", "1", "2", "3"}, bireg::io::TimeUnit::seconds);
  for (Format format : {Format::tum, Format::kitti}) {
    CAPTURE(bireg::io::to_string(format));
    const std::string text = bireg::io::format_trajectory<SE3>(format, Format::tum, times, poses);
    const auto rigid = read_ok<SE3>(text);
    const auto similar = read_ok<Sim3>(text);
    REQUIRE(similar.format == format);
    REQUIRE(similar.observations.size() == rigid.observations.size());
    for (std::size_t i = 0; i < rigid.observations.size(); ++i)
      REQUIRE(similar.observations[i] == rigid.observations[i]);
  }
  std::FILE* sink = std::fopen("/dev/null", "wb");
  REQUIRE(sink);
  std::vector<Sim3::Element> scaled(poses.begin(), poses.end());
  scaled[1].topLeftCorner<3, 3>() *= 2.0;
  const auto error =
      bireg::io::write_trajectory<Sim3>(sink, Format::tum, Format::tum, times, scaled);
  std::fclose(sink);
  REQUIRE(error);
  REQUIRE(error->find("not Sim3") != std::string::npos);
}

TEST_CASE("JSON numbers are never nan or inf", "[io]") {
  REQUIRE(bireg::io::json_number(std::nan("")) == "null");
  REQUIRE(bireg::io::json_number(-HUGE_VAL) == "null");
  REQUIRE(bireg::io::json_number(0.1) == "0.1");
  Eigen::Matrix2d m;
  m << 1, std::nan(""), HUGE_VAL, 2;
  REQUIRE(bireg::io::json_matrix(m) == "[[1, null], [null, 2]]");
}

// Issue 36, defect 6: a trajectory turning through pi. q and -q are the
// same rotation; choosing w >= 0 on every line flips the sign of (x, y, z)
// between two nearby rotations either side of pi. Each written quaternion
// must lie on the side of the previous line's (q_k . q_{k-1} >= 0), the
// first with w >= 0, and every line must still read back as its pose.
TEST_CASE("written quaternions keep their hemisphere through a half turn", "[io]") {
  constexpr double kPi = 3.14159265358979323846;
  for (const bool tilting_axis : {false, true}) {
    CAPTURE(tilting_axis);
    std::vector<SE3::Element> poses;
    std::vector<SO3::Element> rotations;
    std::vector<std::string> seconds, nanoseconds;
    // From 0 to 2.2 pi (through pi, and through 2 pi where q reaches -1);
    // step 0.01 pi, and an angle landing exactly on pi.
    for (int k = 0; k <= 220; ++k) {
      const double angle = 0.01 * kPi * k;
      Eigen::Vector3d axis(1, 2, 3);
      if (tilting_axis) axis += Eigen::Vector3d(std::sin(0.05 * k), 0, std::cos(0.03 * k));
      axis.normalize();
      rotations.push_back(Eigen::AngleAxisd(angle, axis).toRotationMatrix());
      SE3::Element g = SE3::Element::Identity();
      g.topLeftCorner<3, 3>() = rotations.back();
      g.topRightCorner<3, 1>() = Eigen::Vector3d(0.1 * k, -0.02 * k, 1);
      poses.push_back(g);
      seconds.push_back(std::to_string(10 + k) + ".5");
      nanoseconds.push_back(std::to_string(10 + k) + "500000000");
    }
    for (const Format format : {Format::tum, Format::euroc}) {
      CAPTURE(bireg::io::to_string(format));
      const bool euroc = format == Format::euroc;
      const auto times = timestamps_of(euroc ? nanoseconds : seconds, bireg::io::time_unit(format));
      const std::string se3 = bireg::io::format_trajectory<SE3>(format, format, times, poses);
      const std::string so3 = bireg::io::format_trajectory<SO3>(format, format, times, rotations);
      for (const std::string* text : {&se3, &so3}) {
        std::istringstream lines(*text);
        std::string line;
        if (euroc) std::getline(lines, line);  // the header
        std::vector<Eigen::Vector4d> written;  // (w, x, y, z)
        while (std::getline(lines, line)) {
          for (char& c : line)
            if (c == ',') c = ' ';
          std::istringstream numbers(line);
          std::vector<double> v;
          for (double x; numbers >> x;)
            v.push_back(x);
          REQUIRE(v.size() == (euroc ? 17u : 8u));
          written.push_back(euroc ? Eigen::Vector4d(v[4], v[5], v[6], v[7])
                                  : Eigen::Vector4d(v[7], v[4], v[5], v[6]));
        }
        REQUIRE(written.size() == poses.size());
        REQUIRE(written.front()[0] >= 0);
        for (std::size_t k = 0; k < written.size(); ++k) {
          CAPTURE(k);
          const Eigen::Quaterniond q(written[k][0], written[k][1], written[k][2], written[k][3]);
          REQUIRE(std::abs(q.norm() - 1) <= 1e-15 * 8);
          REQUIRE((q.toRotationMatrix() - rotations[k]).norm() <= 1e-14);
          if (k > 0) REQUIRE(written[k].dot(written[k - 1]) >= 0);
        }
        // Through 2 pi the quaternion has turned to -1: w < 0 at the end.
        REQUIRE(written.back()[0] < 0);
      }
    }
  }
}
