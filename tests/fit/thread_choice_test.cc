#include "dwellfit/estimator/fit/thread_choice.h"

#include <sys/sysinfo.h>

#include <atomic>
#include <functional>
#include <thread>
#include <vector>

#include "gtest/gtest.h"

namespace dwellfit {
namespace {

// Probes of the machine: one processor idle besides the caller's, or none.
int OneIdle() { return 1; }
int NoneIdle() { return 0; }

// Runs `count` evaluations whose time [s] in each way is
// `seconds(threaded, evaluation)`; returns how many ran threaded.
int RunEvaluations(ThreadChoice* choice, int count, const std::function<double(bool, int)>& seconds,
                   int first = 0) {
  int threaded_count = 0;
  for (int i = first; i < first + count; ++i) {
    const bool threaded = choice->Next();
    threaded_count += threaded ? 1 : 0;
    choice->Record(threaded, seconds(threaded, i));
  }
  return threaded_count;
}

TEST(ThreadChoice, ANewHistoryStartsOnTheThreadsAndTriesTheCallerAloneAfterFour) {
  ThreadChoiceHistory history;
  ThreadChoice choice(&history, &OneIdle);
  for (int i = 0; i < 4; ++i) {  // the first not timed, then three
    EXPECT_TRUE(choice.Next()) << i;
    choice.Record(true, 1e-3);
  }
  EXPECT_FALSE(choice.Next());  // the trial
}

// A solve's first evaluations are its dearest (cold roots and buffers). A
// trial that falls due as a new choice starts waits for three timed
// evaluations of the preferred way after the first, and is measured against
// their median: the caller alone, 0.96 ms, does not beat threads that take
// 1.2 ms cold, then 0.95 ms, then 0.5-0.6 ms (as on the measured beam,
// where a trial against the first two alone took the evaluations over).
TEST(ThreadChoice, ATrialWaitsForThreeTimedEvaluationsAfterTheColdFirst) {
  ThreadChoiceHistory history;
  history.preferred_way = 1;
  history.trial_interval = ThreadChoice::kTrialInterval;
  history.since_trial = ThreadChoice::kTrialInterval - 3;  // a trial due at the third
  ThreadChoice choice(&history, &OneIdle);
  const auto cooling = [](bool t, int i) {
    if (!t) return 0.96e-3;
    return i == 0 ? 1.2e-3 : i == 1 ? 0.95e-3 : i == 2 ? 0.6e-3 : 0.5e-3;
  };
  const int threaded = RunEvaluations(&choice, 10, cooling);
  EXPECT_TRUE(choice.prefers_threaded());
  EXPECT_EQ(threaded, 9);  // one trial, after the fourth evaluation
}

// Two idle cores: the threads take half the time. After the first trial the
// evaluations stay threaded, and the caller alone is tried ever more rarely.
TEST(ThreadChoice, ThreadsTwiceAsFastStayThreadedWithRarerTrials) {
  ThreadChoiceHistory history;
  ThreadChoice choice(&history, &OneIdle);
  const int threaded =
      RunEvaluations(&choice, 200, [](bool t, int) { return t ? 0.5e-3 : 1.0e-3; });
  EXPECT_TRUE(choice.prefers_threaded());
  EXPECT_EQ(choice.trial_interval(), ThreadChoice::kMaxTrialInterval);
  // Trials after 4, 16, 32, 64 and 64 evaluations.
  EXPECT_EQ(200 - threaded, 5);
}

// A processor idle, the threads slower but not by the margin (1.1 times the
// caller's time): the margin favours the threads, and they keep the
// evaluations through every trial of the caller alone.
TEST(ThreadChoice, WithAnIdleProcessorThreadsNotClearlySlowerStay) {
  ThreadChoiceHistory history;
  ThreadChoice choice(&history, &OneIdle);
  const int threaded =
      RunEvaluations(&choice, 200, [](bool t, int) { return t ? 1.1e-3 : 1.0e-3; });
  EXPECT_TRUE(choice.prefers_threaded());
  // Trials of the caller alone after 4, 16, 32, 64 and 64 evaluations.
  EXPECT_EQ(200 - threaded, 5);
}

// A processor idle, the threads clearly slower (1.5 times the caller's
// time): the caller alone takes over at the first trial, and the threads
// are tried ever more rarely, each trial an evaluation that wakes the
// workers and one that is timed.
TEST(ThreadChoice, ThreadsClearlySlowerGiveWayToTheCallerAlone) {
  ThreadChoiceHistory history;
  ThreadChoice choice(&history, &OneIdle);
  const int threaded =
      RunEvaluations(&choice, 200, [](bool t, int) { return t ? 1.5e-3 : 1.0e-3; });
  EXPECT_FALSE(choice.prefers_threaded());
  EXPECT_EQ(choice.trial_interval(), ThreadChoice::kMaxTrialInterval);
  // The four before the first trial (the first not timed), then trials of
  // two evaluations after waits of 16, 32, 64 and 64.
  EXPECT_EQ(threaded, 4 + 2 * 4);
}

// No processor idle as a trial of the caller alone falls due: the margin
// favours the caller, and threads only 0.9 times its time (a worker sharing
// a core with another program) give the evaluations up; the trials of the
// threads are then put off.
TEST(ThreadChoice, WithNoIdleProcessorThreadsNotClearlyFasterGiveWay) {
  ThreadChoiceHistory history;
  history.preferred_way = 1;
  history.trial_interval = ThreadChoice::kTrialInterval;
  ThreadChoice choice(&history, &NoneIdle);
  const int threaded = RunEvaluations(&choice, 40, [](bool t, int) { return t ? 0.9e-3 : 1.0e-3; });
  EXPECT_FALSE(choice.prefers_threaded());
  EXPECT_EQ(threaded, 15);  // the trial at the 16th, and none after it
  EXPECT_EQ(choice.trial_interval(), 2 * ThreadChoice::kTrialInterval);
}

// The evaluations grow cheaper as the solve goes on, the threads 1.4 times
// the caller's time at every moment: a trial is measured against the
// caller's evaluations just before it, not older, dearer ones, so the drift
// does not make the threads look faster than they are.
TEST(ThreadChoice, ADriftingCostIsNotTakenForFasterThreads) {
  ThreadChoiceHistory history;
  history.preferred_way = 2;  // the caller alone
  history.trial_interval = ThreadChoice::kTrialInterval;
  ThreadChoice choice(&history, &OneIdle);
  const auto drifting = [](bool t, int i) { return (t ? 1.4 : 1.0) * (2.0e-3 - 0.01e-3 * i); };
  const int threaded = RunEvaluations(&choice, 120, drifting);
  EXPECT_FALSE(choice.prefers_threaded());
  EXPECT_EQ(threaded, 2 * 3);  // trials of two after 16, 32 and 64 evaluations
}

// A trial of the threads starts with an evaluation that wakes the workers,
// which is not timed: held up (a worker asleep is slow to join), it does
// not lose the trial; the next evaluation, threaded too, decides.
TEST(ThreadChoice, ATrialOfTheThreadsFirstWakesTheWorkers) {
  ThreadChoiceHistory history;
  history.preferred_way = 2;
  history.trial_interval = ThreadChoice::kTrialInterval;
  ThreadChoice choice(&history, &OneIdle);
  EXPECT_EQ(RunEvaluations(&choice, 15, [](bool t, int) { return t ? 0.5e-3 : 1e-3; }), 0);
  EXPECT_TRUE(choice.Next());
  choice.Record(true, 5e-3);  // the workers slow to wake
  EXPECT_FALSE(choice.prefers_threaded());
  EXPECT_TRUE(choice.Next());
  choice.Record(true, 0.5e-3);
  EXPECT_TRUE(choice.prefers_threaded());
}

// One threaded evaluation the machine held up, just before a trial of the
// caller alone, does not hand the evaluations to the caller: the trial is
// measured against the median of the last three.
TEST(ThreadChoice, OneHeldUpEvaluationDoesNotDecide) {
  ThreadChoiceHistory history;
  ThreadChoice choice(&history, &OneIdle);
  RunEvaluations(&choice, 10, [](bool t, int) { return t ? 0.5e-3 : 1.0e-3; });
  ASSERT_TRUE(choice.prefers_threaded());
  // The next trial comes after 16 evaluations: hold up the one before it.
  RunEvaluations(
      &choice, 16, [](bool t, int i) { return t ? (i == 24 ? 5e-3 : 0.5e-3) : 0.9e-3; }, 10);
  EXPECT_TRUE(choice.prefers_threaded());
}

// A trial that wins by luck is undone when the next three evaluations on
// the new way are slower than the old way was.
TEST(ThreadChoice, ASwitchThatDoesNotHoldIsUndone) {
  ThreadChoiceHistory history;
  history.preferred_way = 2;
  history.trial_interval = ThreadChoice::kTrialInterval;
  ThreadChoice choice(&history, &OneIdle);
  RunEvaluations(&choice, 15, [](bool t, int) { return t ? 2e-3 : 1e-3; });
  // The trial (evaluations 15, waking the workers, and 16) is lucky; the
  // three after it are not.
  RunEvaluations(
      &choice, 2, [](bool t, int) { return t ? 0.5e-3 : 1e-3; }, 15);
  EXPECT_TRUE(choice.prefers_threaded());
  const int threaded = RunEvaluations(
      &choice, 3, [](bool t, int) { return t ? 2e-3 : 1e-3; }, 17);
  EXPECT_EQ(threaded, 3);
  EXPECT_FALSE(choice.prefers_threaded());
  EXPECT_EQ(choice.trial_interval(), 2 * ThreadChoice::kTrialInterval);
}

// With no idle processor the threads are not tried: the caller alone runs
// every evaluation, and each trial put off doubles the wait as a lost one
// would (16, 32, then 64), so the probe is read rarely; once a processor is
// idle the next trial runs.
TEST(ThreadChoice, NoIdleProcessorPutsOffTheTrialsOfTheThreads) {
  ThreadChoiceHistory history;
  history.preferred_way = 2;  // the caller alone
  history.trial_interval = ThreadChoice::kTrialInterval;
  const auto twice_as_fast = [](bool t, int) { return t ? 0.5e-3 : 1.0e-3; };
  {
    ThreadChoice busy(&history, &NoneIdle);
    // Put off at evaluations 16, 48 and 112 (waits of 16, 32 and 64).
    EXPECT_EQ(RunEvaluations(&busy, 120, twice_as_fast), 0);
    EXPECT_FALSE(busy.prefers_threaded());
    EXPECT_EQ(busy.trial_interval(), ThreadChoice::kMaxTrialInterval);
  }
  ThreadChoice idle(&history, &OneIdle);
  // The next trial falls due at evaluation 176 (the 56th of these, which
  // wakes the workers), wins at the 57th and holds.
  const int threaded = RunEvaluations(&idle, 60, twice_as_fast, 120);
  EXPECT_TRUE(idle.prefers_threaded());
  EXPECT_EQ(threaded, 60 - 55);
}

// A probe that cannot read the machine (-1) leaves the trials as they are.
TEST(ThreadChoice, AnUnreadableMachineStillTriesTheThreads) {
  ThreadChoiceHistory history;
  history.preferred_way = 2;
  history.trial_interval = ThreadChoice::kTrialInterval;
  ThreadChoice choice(&history, [] { return -1; });
  EXPECT_EQ(RunEvaluations(&choice, 17, [](bool t, int) { return t ? 0.5e-3 : 1.0e-3; }), 2);
  EXPECT_TRUE(choice.prefers_threaded());
}

// The probe of this machine reads a count: at least zero, and not more idle
// processors than the machine has besides the caller's.
TEST(ThreadChoice, IdleProcessorsReadsThisMachine) {
  const int idle = IdleProcessors();
  ASSERT_GE(idle, 0) << "/proc/loadavg unreadable";
  EXPECT_LT(idle, get_nprocs());
}

// Threads of this process that spin are counted as its own runnable ones
// (which the probe leaves out of the machine's load), beside the caller.
TEST(ThreadChoice, OwnRunnableThreadsCountsThisProcessesSpinningThreads) {
  std::atomic<bool> stop{false};
  std::atomic<int> started{0};
  std::vector<std::thread> spinning;
  for (int i = 0; i < 2; ++i) {
    spinning.emplace_back([&] {
      started.fetch_add(1);
      while (!stop.load(std::memory_order_relaxed)) {
      }
    });
  }
  while (started.load() < 2) std::this_thread::yield();
  const int runnable = OwnRunnableThreads();
  stop = true;
  for (std::thread& thread : spinning) thread.join();
  EXPECT_GE(runnable, 3);
}

// A history nobody has used yet starts on the caller alone where, as its
// first evaluation comes, no processor is idle, and the trials of the
// threads wait for one; on the threads where one is.
TEST(ThreadChoice, ANewHistoryStartsOnTheCallerAloneWhereNoProcessorIsIdle) {
  const auto twice_as_fast = [](bool t, int) { return t ? 0.5e-3 : 1.0e-3; };
  ThreadChoiceHistory busy_history;
  ThreadChoice busy(&busy_history, &NoneIdle);
  EXPECT_EQ(RunEvaluations(&busy, 50, twice_as_fast), 0);
  EXPECT_FALSE(busy.prefers_threaded());
  ThreadChoiceHistory idle_history;
  ThreadChoice idle(&idle_history, &OneIdle);
  EXPECT_TRUE(idle.Next());
}

// The next choice of one history goes on from where the last left off.
TEST(ThreadChoice, TheNextChoiceOfAHistoryGoesOnFromTheLast) {
  ThreadChoiceHistory history;
  {
    ThreadChoice first(&history, &OneIdle);
    RunEvaluations(&first, 40, [](bool t, int) { return t ? 1.5e-3 : 1.0e-3; });
    ASSERT_FALSE(first.prefers_threaded());
  }
  ThreadChoice next(&history, &OneIdle);
  EXPECT_FALSE(next.prefers_threaded());
  EXPECT_EQ(next.trial_interval(), 2 * ThreadChoice::kTrialInterval);
  EXPECT_FALSE(next.Next());
}

}  // namespace
}  // namespace dwellfit
