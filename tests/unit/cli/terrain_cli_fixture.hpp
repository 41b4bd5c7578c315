#pragma once
// A test of the real marsala-terrain binary (MARSALA_TERRAIN_BIN): runs it in a folder of its own, with its exit code,
// stdout and stderr.

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

namespace marsala::test {

/// What one run of the binary gave.
struct CliRun {
  int exit_code = -1;
  std::string out;
  std::string err;
};

/// The whole of a file ("" when it cannot be read).
inline std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

/// A fixture with a fresh folder per test, <TempDir>/terrain_cli_<suite>_<test>/.
class TerrainCliFixture : public ::testing::Test {
 protected:
  void SetUp() override {
    const ::testing::TestInfo* test = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = ::testing::TempDir() + "terrain_cli_" + test->test_suite_name() + "_" + test->name() + "/";
    ASSERT_EQ(std::system(("mkdir -p '" + dir_ + "'").c_str()), 0);
  }

  /// A file of the test's folder.
  std::string path(const std::string& name) const { return dir_ + name; }

  /// Runs `marsala-terrain ARGS` (a shell word list).
  CliRun run(const std::string& args) const {
    const std::string out = path("stdout.txt"), err = path("stderr.txt");
    const std::string command = std::string(MARSALA_TERRAIN_BIN) + " " + args + " >'" + out + "' 2>'" + err + "'";
    const int status = std::system(command.c_str());
    CliRun r;
    r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    r.out = slurp(out);
    r.err = slurp(err);
    return r;
  }

  /// Writes `text` into a file of the test's folder.
  void write(const std::string& name, const std::string& text) const { std::ofstream(path(name)) << text; }

  std::string dir_;
};

}  // namespace marsala::test
