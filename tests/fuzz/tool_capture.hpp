// What the tools' fuzz targets share: a tool's entry point called
// in-process with its stdout and stderr captured, and the properties every
// run of a tool must have whatever its input.
//
// The capture swaps glibc's stdout and stderr FILE pointers (assignable in
// glibc) for memory streams around the call: the tools print only through
// those, while the sanitizers and libFuzzer write their reports to file
// descriptor 2, which stays the terminal.
#pragma once

#include <cctype>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

#include <unistd.h>

#include "require.hpp"

namespace bireg_fuzz {

struct ToolRun {
  int exit_code = 0;
  std::string out;  // what the tool printed on stdout
  std::string err;  // ... and on stderr
};

inline ToolRun run_tool(int (*entry)(int, char**), const std::vector<std::string>& arguments) {
  std::vector<std::string> storage = arguments;
  std::vector<char*> argv;
  for (std::string& a : storage)
    argv.push_back(a.data());
  argv.push_back(nullptr);

  char* out_buffer = nullptr;
  char* err_buffer = nullptr;
  std::size_t out_size = 0, err_size = 0;
  std::FILE* out = open_memstream(&out_buffer, &out_size);
  std::FILE* err = open_memstream(&err_buffer, &err_size);
  require(out && err);
  std::FILE* const saved_out = stdout;
  std::FILE* const saved_err = stderr;
  stdout = out;
  stderr = err;
  ToolRun run;
  run.exit_code = entry(static_cast<int>(storage.size()), argv.data());
  stdout = saved_out;
  stderr = saved_err;
  std::fclose(out);
  std::fclose(err);
  run.out.assign(out_buffer, out_size);
  run.err.assign(err_buffer, err_size);
  std::free(out_buffer);
  std::free(err_buffer);
  return run;
}

// A private directory for the input and output files, made once.
inline const std::string& scratch_directory() {
  static const std::string directory = [] {
    char name[] = "/tmp/bireg-fuzz-XXXXXX";
    require(mkdtemp(name) != nullptr);
    return std::string(name);
  }();
  return directory;
}

inline void write_file(const std::string& path, const std::string& text) {
  std::ofstream file(path, std::ios::binary | std::ios::trunc);
  file.write(text.data(), static_cast<std::streamsize>(text.size()));
  require(static_cast<bool>(file));
}

// The file's text; empty when it does not exist (and removes it, so that
// the next run starts without it).
inline std::string take_file(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  std::string text((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  std::remove(path.c_str());
  return text;
}

// Every line of stderr starts with the tool's name, is printable ASCII
// and bounded (messages quote bounded excerpts of the input), and ends
// with a newline.
inline void require_messages(const std::string& err, const std::string& tool) {
  require(err.empty() || err.back() == '\n');
  std::istringstream lines(err);
  std::string line;
  while (std::getline(lines, line)) {
    require(line.compare(0, tool.size() + 2, tool + ": ") == 0);
    require(line.size() <= 1000);
    for (char c : line)
      require(c >= 0x20 && c < 0x7f);
  }
}

// The input-format options both tools take, from a 3-bit code: the
// format detected from the content (0, 6, 7), matrix, tum, euroc, kitti,
// or kitti with `input` itself as the --times file (5).
inline std::vector<std::string> format_options(unsigned code, const std::string& input) {
  static const char* const kFormats[] = {nullptr, "matrix", "tum", "euroc", "kitti", "kitti"};
  if (code == 0 || code > 5) return {};
  std::vector<std::string> options = {"--format", kFormats[code]};
  if (code == 5) options.insert(options.end(), {"--times", input});
  return options;
}

inline std::size_t count_lines(const std::string& text) {
  std::size_t lines = 0;
  for (char c : text)
    lines += c == '\n';
  return lines;
}

// A refusal (exit code 2): nothing on stdout, one line on stderr.
inline void require_refusal(const ToolRun& run, const std::string& tool) {
  require(run.out.empty());
  require_messages(run.err, tool);
  require(count_lines(run.err) == 1);
}

// The key whose value starts at text[value] ("key": value), or "".
inline std::string key_before(const std::string& text, std::size_t value) {
  const std::size_t colon = text.rfind(':', value);
  if (colon == std::string::npos || colon == 0 || text[colon - 1] != '"') return "";
  const std::size_t open = text.rfind('"', colon - 2);
  return open == std::string::npos ? "" : text.substr(open + 1, colon - 2 - open);
}

// One JSON object whose only bare words are true and false, and null where
// the key is one of `absent_keys` (a value absent by a documented rule,
// such as no recommended model): every number finite (the tools print no
// nan or inf, and null for a number only by such a rule), brackets
// balanced, strings closed.
inline void require_json_object(const std::string& text,
                                const std::vector<std::string>& absent_keys = {}) {
  require(!text.empty() && text.front() == '{');
  std::vector<char> open;
  bool in_string = false;
  std::string word;
  std::size_t word_start = 0;
  const auto end_word = [&] {
    if (word == "null") {
      const std::string key = key_before(text, word_start);
      bool absent = false;
      for (const std::string& k : absent_keys)
        absent = absent || k == key;
      require(absent);
    } else {
      require(word.empty() || word == "true" || word == "false");
    }
    word.clear();
  };
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (in_string) {
      if (c == '\\') {
        ++i;
      } else if (c == '"') {
        in_string = false;
      } else {
        require(static_cast<unsigned char>(c) >= 0x20);
      }
      continue;
    }
    if (std::isalpha(static_cast<unsigned char>(c)) && c != 'e' && c != 'E') {
      if (word.empty()) word_start = i;
      word += c;
      continue;
    }
    if ((c == 'e' || c == 'E') && !word.empty()) {
      word += c;
      continue;
    }
    end_word();
    if (c == '"') {
      in_string = true;
    } else if (c == '{' || c == '[') {
      open.push_back(c);
    } else if (c == '}' || c == ']') {
      require(!open.empty() && open.back() == (c == '}' ? '{' : '['));
      open.pop_back();
      if (open.empty()) {
        // The object ends the output, followed by one newline.
        require(text.substr(i + 1) == "\n");
        return;
      }
    }
  }
  require(false);  // never closed
}

// Text a tool wrote for numbers (a trajectory, a CSV): no nan or inf,
// whatever their case.
inline void require_finite_text(const std::string& text) {
  std::string lower;
  for (char c : text)
    lower += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  require(lower.find("nan") == std::string::npos && lower.find("inf") == std::string::npos);
}

}  // namespace bireg_fuzz
