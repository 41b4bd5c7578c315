// Run folders are owned (docs/runtime.md#run-folders): a second lock on a held folder is refused naming the holder's
// pid, in this process or another; the lock dies with its holder, a SIGKILL included, and leaves nothing to clean.

#include "marsala/world_server/records/output_lock.hpp"

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>

namespace marsala::world_server {
namespace {

namespace fs = std::filesystem;

fs::path fresh_dir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / fmt::format("marsala_output_lock_{}_{}", name, ::getpid());
  fs::remove_all(dir);
  return dir;
}

std::string refusal(const fs::path& dir) {
  try {
    OutputLock second(dir.string());
  } catch (const FolderInUse& e) {
    return e.what();
  }
  return {};
}

TEST(OutputLock, MakesTheFolderAndRefusesASecondLockNamingThePid) {
  const fs::path dir = fresh_dir("second") / "run";
  {
    OutputLock first(dir.string());
    EXPECT_TRUE(fs::is_directory(dir));
    std::ifstream in(dir / kOutputLockFile);
    long pid = 0;
    in >> pid;
    EXPECT_EQ(pid, static_cast<long>(::getpid()));
    const std::string message = refusal(dir);
    EXPECT_NE(message.find(fmt::format("pid {}", ::getpid())), std::string::npos) << message;
    EXPECT_NE(message.find(dir.string()), std::string::npos) << message;
  }
  EXPECT_NO_THROW(OutputLock again(dir.string()));  // released with its holder
  fs::remove_all(dir.parent_path());
}

TEST(OutputLock, AnotherProcessHoldsItUntilItIsKilled) {
  const fs::path dir = fresh_dir("child");
  int ready[2];
  ASSERT_EQ(::pipe(ready), 0);
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    OutputLock held(dir.string());
    const char byte = 1;
    (void)!::write(ready[1], &byte, 1);
    for (;;) ::pause();
  }
  char byte = 0;
  ASSERT_EQ(::read(ready[0], &byte, 1), 1);
  const std::string message = refusal(dir);
  EXPECT_NE(message.find(fmt::format("pid {}", child)), std::string::npos) << message;
  ::kill(child, SIGKILL);
  int status = 0;
  ::waitpid(child, &status, 0);
  EXPECT_NO_THROW(OutputLock taken(dir.string()));  // nothing to clean after a SIGKILL
  ::close(ready[0]);
  ::close(ready[1]);
  fs::remove_all(dir);
}

TEST(OutputLock, AFolderThatCannotBeMadeIsAnIoError) {
  const fs::path dir = fresh_dir("file");
  fs::create_directories(dir);
  std::ofstream(dir / "plain") << "x";
  EXPECT_THROW(OutputLock bad((dir / "plain" / "run").string()), IoError);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace marsala::world_server
