// bireg io: reading text line by line with bounded memory and honest errors.
//
// A LineReader pulls bytes from a ByteSource in blocks and hands out one line
// at a time as a view into its buffer (valid until the next call). It
//   * reports a read error of the source as an error, never as end of input;
//   * refuses a line longer than max_line_length bytes (kMaxLineLength = 1 MiB
//     by default), naming its line number, so memory stays bounded whatever
//     the input (the buffer never exceeds max_line_length + one block);
//   * refuses binary input (a NUL byte) as soon as the block holding it is
//     read, naming the line;
//   * counts lines in 64 bits.
// Lines end at '\n'; a trailing '\r' is dropped; the last line needs no '\n'.
// Uses the standard library only and never throws on bad input.
#pragma once

#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <istream>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#if defined(__unix__) || defined(__APPLE__)
#include <sys/stat.h>
#endif

namespace bireg {
namespace io {

// The longest line a reader accepts, in bytes (without its end of line).
inline constexpr std::size_t kMaxLineLength = std::size_t{1} << 20;

// A problem with the input: the 1-based line, or 0 for the input as a whole.
struct ParseError {
  std::uint64_t line = 0;
  std::string message;
};

// A bounded, escaped excerpt of untrusted text for an error message: at most
// max_chars bytes, printable ASCII kept, everything else (control characters,
// escape sequences, bytes above 127) written as \xNN, quotes and backslashes
// escaped, "..." appended when cut; in single quotes.
inline std::string quote_excerpt(std::string_view text, std::size_t max_chars = 40) {
  std::string out = "'";
  const std::size_t n = text.size() < max_chars ? text.size() : max_chars;
  for (std::size_t i = 0; i < n; ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    if (c == '\'' || c == '\\') {
      out += '\\';
      out += static_cast<char>(c);
    } else if (c >= 0x20 && c < 0x7f) {
      out += static_cast<char>(c);
    } else {
      static constexpr char kHex[] = "0123456789abcdef";
      out += "\\x";
      out += kHex[c >> 4];
      out += kHex[c & 15];
    }
  }
  if (text.size() > n) out += "...";
  return out + "'";
}

// Where bytes come from. read() returns the number of bytes stored (at most
// size); 0 means the end of the input or an error, told apart by error().
class ByteSource {
 public:
  virtual ~ByteSource() = default;
  virtual std::size_t read(char* data, std::size_t size) = 0;
  // Empty unless reading failed.
  virtual std::string error() const = 0;
  // How many bytes are left to read, as far as the source knows (0:
  // unknown). Only a hint for reserving memory: reading stops at read()'s 0.
  virtual std::size_t size_hint() const { return 0; }
};

// A C stream (a file opened with std::fopen, or stdin).
class FileSource final : public ByteSource {
 public:
  explicit FileSource(std::FILE* file) : file_(file) {
#if defined(__unix__) || defined(__APPLE__)
    struct stat status;
    if (file_ && fstat(fileno(file_), &status) == 0 && S_ISREG(status.st_mode)) {
      const long at = std::ftell(file_);
      if (at >= 0 && status.st_size > at) {
        const auto left = static_cast<std::uintmax_t>(status.st_size - at);
        constexpr std::size_t kLargest = std::numeric_limits<std::size_t>::max();
        size_ = left > kLargest ? kLargest : static_cast<std::size_t>(left);
      }
    }
#endif
  }
  std::size_t read(char* data, std::size_t size) override {
    if (!file_ || failed_) return 0;
    errno = 0;
    const std::size_t got = std::fread(data, 1, size, file_);
    if (got < size && std::ferror(file_)) {
      failed_ = true;
      error_ = std::string("read error: ") +
               (errno != 0 ? std::strerror(errno) : "the stream reported an error");
    }
    read_ += got;
    return got;
  }
  std::string error() const override {
    return error_;
  }
  std::size_t size_hint() const override {
    return size_ > read_ ? size_ - read_ : 0;
  }

 private:
  std::FILE* file_;
  // A regular file's bytes from the position at construction (0: not a
  // regular file), and the bytes read since: a hint, stale if the file
  // changes or someone else reads the FILE.
  std::size_t size_ = 0, read_ = 0;
  bool failed_ = false;
  std::string error_;
};

// A C++ stream. A stream that goes bad (badbit) is a read error.
class StreamSource final : public ByteSource {
 public:
  explicit StreamSource(std::istream& in) : in_(in) {}
  std::size_t read(char* data, std::size_t size) override {
    if (in_.bad() || in_.eof()) return 0;
    in_.read(data, static_cast<std::streamsize>(size));
    const auto got = static_cast<std::size_t>(in_.gcount());
    if (in_.bad()) error_ = "read error";
    return got;
  }
  std::string error() const override { return error_; }

 private:
  std::istream& in_;
  std::string error_;
};

// Text already in memory (the view must outlive the source).
class MemorySource final : public ByteSource {
 public:
  explicit MemorySource(std::string_view text) : text_(text) {}
  template <std::size_t N>
  explicit MemorySource(const char (&literal)[N]) : text_(literal, N - 1) {}
  explicit MemorySource(std::string&&) = delete;  // would dangle
  std::size_t read(char* data, std::size_t size) override {
    const std::size_t n = size < text_.size() - at_ ? size : text_.size() - at_;
    if (n > 0) std::memcpy(data, text_.data() + at_, n);
    at_ += n;
    return n;
  }
  std::string error() const override { return {}; }
  std::size_t size_hint() const override { return text_.size() - at_; }

 private:
  std::string_view text_;
  std::size_t at_ = 0;
};

class LineReader {
 public:
  explicit LineReader(ByteSource& source, std::size_t max_line_length = kMaxLineLength,
                      std::size_t block_size = std::size_t{1} << 16)
      : source_(source), max_line_(max_line_length), block_(block_size > 0 ? block_size : 1) {
    buffer_.resize(block_);
  }

  // The next line in `line`, or false at the end of the input or on an
  // error (then error() says which line and why).
  bool next(std::string_view& line) {
    if (error_ || done_) return false;
    for (;;) {
      // Look for the end of the line among the bytes not yet scanned.
      const char* base = buffer_.data();
      const char* newline =
          static_cast<const char*>(std::memchr(base + scanned_, '\n', filled_ - scanned_));
      const std::size_t stop = newline ? static_cast<std::size_t>(newline - base) : filled_;
      if (const void* nul = std::memchr(base + scanned_, '\0', stop - scanned_)) {
        (void)nul;
        return fail(line_number_ + 1, "binary input (a NUL byte); expected text");
      }
      scanned_ = stop;
      if (newline) {
        std::size_t length = stop - begin_;
        if (length > max_line_) return fail_too_long();
        if (length > 0 && base[stop - 1] == '\r') --length;
        line = std::string_view(base + begin_, length);
        begin_ = scanned_ = stop + 1;
        ++line_number_;
        return true;
      }
      if (filled_ - begin_ > max_line_) return fail_too_long();
      if (eof_) {
        done_ = true;
        if (begin_ == filled_) return false;
        std::size_t length = filled_ - begin_;
        if (base[filled_ - 1] == '\r') --length;
        line = std::string_view(base + begin_, length);
        begin_ = scanned_ = filled_;
        ++line_number_;
        return true;
      }
      refill();
      if (error_) return false;
    }
  }

  // Bytes not yet handed out, as far as the source knows (a hint).
  std::size_t remaining_hint() const { return (filled_ - begin_) + source_.size_hint(); }

  // Lines handed out so far (the number of the last one).
  std::uint64_t line_number() const { return line_number_; }
  const std::optional<ParseError>& error() const { return error_; }

 private:
  void refill() {
    // Move the partial line to the front, then append one block.
    if (begin_ > 0) {
      std::memmove(buffer_.data(), buffer_.data() + begin_, filled_ - begin_);
      filled_ -= begin_;
      scanned_ -= begin_;
      begin_ = 0;
    }
    if (buffer_.size() < filled_ + block_) buffer_.resize(filled_ + block_);
    const std::size_t got = source_.read(buffer_.data() + filled_, block_);
    filled_ += got;
    if (got == 0) {
      const std::string problem = source_.error();
      if (!problem.empty()) {
        fail(line_number_ + 1, problem);
      } else {
        eof_ = true;
      }
    }
  }

  bool fail(std::uint64_t line, std::string message) {
    error_ = ParseError{line, std::move(message)};
    return false;
  }
  bool fail_too_long() {
    return fail(line_number_ + 1,
                "line longer than " + std::to_string(max_line_) + " bytes (the limit)");
  }

  ByteSource& source_;
  std::size_t max_line_, block_;
  std::vector<char> buffer_;
  std::size_t begin_ = 0, scanned_ = 0, filled_ = 0;
  std::uint64_t line_number_ = 0;
  bool eof_ = false, done_ = false;
  std::optional<ParseError> error_;
};

}  // namespace io
}  // namespace bireg
