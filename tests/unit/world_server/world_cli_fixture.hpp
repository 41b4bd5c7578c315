#pragma once
// A test fixture that runs marsala-world's command line in process, as main() does, in a fresh folder per test, alone
// or beside a walking fake agent.

#include <gtest/gtest.h>
#include <unistd.h>

#include <atomic>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "marsala/world_server/runtime/world_cli.hpp"
#include "unit/world_server/fake_agent.hpp"
#include "unit/world_server/world_fixtures.hpp"

namespace marsala::world_server::testing {

class WorldCliFixture : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = std::filesystem::temp_directory_path() /
           ("marsala_" + std::string(info->test_suite_name()) + "_" + std::to_string(::getpid()) + "_" + info->name());
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  /// Writes `text` to dir_/name and returns its path.
  std::string write(const std::string& name, const std::string& text) const {
    const std::filesystem::path p = dir_ / name;
    std::ofstream(p) << text;
    return p.string();
  }
  /// Runs marsala-world with `args` on the in-process bus of `domain` beside one walking fake agent in slot 1 of the
  /// small scenario (--agents 1 --quiet added); returns the world's exit code.
  int run_beside_walker(int domain, std::vector<std::string> args) {
    args.insert(args.end(), {"--agents", "1", "--dds", "inprocess", "--domain", std::to_string(domain), "--quiet"});
    int rc = -1;
    std::thread world([&] { rc = run(args); });
    FakeAgentConfig c;
    c.domain = domain;
    c.id = 1;
    c.session = 5;
    c.body = small_scenario().robot_for(1).body;
    FakeAgent agent(c);
    world.join();
    agent.join();
    return rc;
  }
  /// marsala-world with `args`; out_ and err_ hold what it printed.
  int run(std::vector<std::string> args) {
    args.insert(args.begin(), "marsala-world");
    std::vector<const char*> argv;
    for (const auto& a : args) argv.push_back(a.c_str());
    out_.str("");
    err_.str("");
    return run_world_cli(static_cast<int>(argv.size()), argv.data(), stop_, out_, err_);
  }

  std::filesystem::path dir_;
  std::atomic<bool> stop_{false};
  std::ostringstream out_, err_;
};

}  // namespace marsala::world_server::testing
