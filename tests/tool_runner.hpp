// Running a built command-line tool from a test: its exit code, stdout and
// stderr, and the test's scratch and data directories (BIREG_TEST_WORK_DIR,
// BIREG_TEST_DATA_DIR, set by tests/CMakeLists.txt), and reading numbers
// and strings out of their JSON. Shared by the tests of the tools.
#pragma once

#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "catch.hpp"

namespace bireg_test {

struct Run {
  int exit_code = -1;
  std::string out, err;
};

inline std::string slurp(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::stringstream buffer;
  buffer << in.rdbuf();
  return buffer.str();
}

inline std::filesystem::path work_dir() {
  const std::filesystem::path dir = std::filesystem::path(BIREG_TEST_WORK_DIR);
  std::filesystem::create_directories(dir);
  return dir;
}

inline std::string data(const std::string& name) {
  return std::string(BIREG_TEST_DATA_DIR) + "/" + name;
}

// Runs `executable arguments` through the shell, capturing both streams.
inline Run run_executable(const std::string& executable, const std::string& arguments) {
  // ctest runs test cases in parallel processes: one pair of files each.
  const std::string tag = std::to_string(static_cast<long>(getpid()));
  const std::filesystem::path out = work_dir() / ("stdout_" + tag + ".txt");
  const std::filesystem::path err = work_dir() / ("stderr_" + tag + ".txt");
  const std::string command = "\"" + executable + "\" " + arguments + " > \"" + out.string() +
                              "\" 2> \"" + err.string() + "\"";
  const int status = std::system(command.c_str());
  Run run;
  run.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  run.out = slurp(out);
  run.err = slurp(err);
  return run;
}

// The numbers of the JSON value after "key": (a number or nested arrays),
// in order. Enough for the objects the tools print (the first "key" in the text).
inline std::vector<double> json_numbers(const std::string& json, const std::string& key) {
  const std::size_t at = json.find("\"" + key + "\":");
  REQUIRE(at != std::string::npos);
  std::size_t i = at + key.size() + 3;
  std::vector<double> numbers;
  int depth = 0;
  do {
    while (json[i] == ' ' || json[i] == ',' || json[i] == '\n')
      ++i;
    if (json[i] == '[') {
      ++depth;
      ++i;
    } else if (json[i] == ']') {
      --depth;
      ++i;
    } else {
      char* end = nullptr;
      numbers.push_back(std::strtod(json.c_str() + i, &end));
      REQUIRE(end != json.c_str() + i);
      i = static_cast<std::size_t>(end - json.c_str());
    }
  } while (depth > 0);
  return numbers;
}

inline std::string json_string(const std::string& json, const std::string& key) {
  const std::size_t at = json.find("\"" + key + "\": \"");
  REQUIRE(at != std::string::npos);
  const std::size_t start = at + key.size() + 5;
  return json.substr(start, json.find('"', start) - start);
}

}  // namespace bireg_test
