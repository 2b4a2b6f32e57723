#include "dwellfit/estimator/matfile/child_process.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <stdexcept>
#include <string>

namespace dwellfit {
namespace {

using ::testing::HasSubstr;
using namespace std::chrono_literals;

TEST(ChildProcessTest, HandsBackWhatTheWorkReturns) {
  // Larger than a pipe's buffer (64 KiB), so that the caller must read while
  // the child writes.
  std::string expected(3 << 20, '\0');
  for (std::size_t i = 0; i < expected.size(); ++i) expected[i] = static_cast<char>(i * 7919 % 251);
  const ChildOutcome outcome = RunInChildProcess([&] { return expected; }, 60s);
  EXPECT_TRUE(outcome.completed) << outcome.failure;
  EXPECT_EQ(outcome.bytes, expected);
  EXPECT_EQ(outcome.failure, "");
}

TEST(ChildProcessTest, TheWorkRunsInAnotherProcess) {
  const pid_t caller = getpid();
  int touched = 0;
  const ChildOutcome outcome = RunInChildProcess(
      [&] {
        touched = 1;
        return std::to_string(getpid());
      },
      60s);
  ASSERT_TRUE(outcome.completed) << outcome.failure;
  EXPECT_NE(outcome.bytes, std::to_string(caller));
  EXPECT_EQ(touched, 0);  // the child's memory is its own
}

TEST(ChildProcessTest, ACrashIsAFailureNamingTheSignal) {
  const ChildOutcome segv = RunInChildProcess(
      [] {
        raise(SIGSEGV);
        return std::string("never");
      },
      60s);
  EXPECT_FALSE(segv.completed);
  EXPECT_THAT(segv.failure, HasSubstr("stopped by signal " + std::to_string(SIGSEGV)));
  EXPECT_EQ(segv.bytes, "");
  const ChildOutcome abort_outcome = RunInChildProcess([]() -> std::string { std::abort(); }, 60s);
  EXPECT_FALSE(abort_outcome.completed);
  EXPECT_THAT(abort_outcome.failure, HasSubstr("stopped by signal " + std::to_string(SIGABRT)));
}

TEST(ChildProcessTest, AnExceptionOfTheWorkIsAFailure) {
  const ChildOutcome outcome =
      RunInChildProcess([]() -> std::string { throw std::runtime_error("damaged"); }, 60s);
  EXPECT_FALSE(outcome.completed);
  EXPECT_EQ(outcome.failure, "failed");
}

TEST(ChildProcessTest, AnExitOfTheWorkIsAFailure) {
  const ChildOutcome outcome = RunInChildProcess([]() -> std::string { _exit(3); }, 60s);
  EXPECT_FALSE(outcome.completed);
  EXPECT_EQ(outcome.failure, "ended with exit code 3");
}

TEST(ChildProcessTest, AHangIsKilledAtTheLimit) {
  const ChildOutcome outcome = RunInChildProcess(
      [] {
        for (;;) pause();
        return std::string();
      },
      200ms);
  EXPECT_FALSE(outcome.completed);
  EXPECT_EQ(outcome.failure, "took longer than 0.2 s");
}

}  // namespace
}  // namespace dwellfit
