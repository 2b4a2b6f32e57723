// ThreadChoice: whether the next evaluation of a ParallelResidualEvaluator
// runs on its threads or in the caller alone, from the times of the last
// evaluations of each way.
//
// A solve's evaluations drift in cost as it goes on (the clamped beam's
// vertical stage from 0.9 ms down to 0.4, up to 0.8 and down to 0.3 ms), so
// times taken at different moments compare the moments, not the ways. The
// choice therefore changes only by trial: every so often one evaluation runs
// the way not preferred, and its time is compared with the median of the
// preferred way's last three evaluations, the ones just before it (the
// median: one evaluation the machine held up does not decide), so it waits
// until this choice has timed three; the first evaluation a choice sees (its
// solve's first, the roots and buffers cold, the dearest of the solve) is
// not timed. Taken just after a dear start, a trial of either way would
// look faster than it is: on the measured beam the caller alone won the
// vertical stage's first trial against the threads' first two evaluations
// and kept the evaluations for some fifty more. A trial that
// wins switches the way, and the next three evaluations confirm it against
// the same median, or the way switches back. A trial that loses doubles the
// wait before the next (16, 32, then 64 evaluations), so a machine that stays
// as it is pays for few. The threads must be kThreadedMargin times faster: a
// threaded evaluation also costs time outside itself (the workers that wake,
// and that look for more work before they sleep, take the processor from the
// caller's serial work on a busy machine).
//
// What the choice has come to (the way, the wait between trials, the count
// since the last) is kept in a ThreadChoiceHistory, which the next choice
// of the same history goes on from: the evaluators of one residual kind
// share one (ForKind), so a study of many fits pays for the trials once. A
// history nobody has used yet starts on the threads and tries the caller
// alone after four evaluations (one untimed, three timed), unless no
// processor is idle as its first evaluation comes: then the other way
// round, the caller alone first. An evaluation some residual failed at is
// not timed (its rows stop early: on the beam 0.02 ms against 0.18, which
// as a trial of the caller alone won the algebraic stage for it). Which way
// runs changes no value.
//
// A trial of the threads that falls due while the caller alone is preferred
// first asks the machine whether a processor is idle (IdleProcessors): with
// none, a worker would only share a processor with the caller or with
// another program, and the threaded evaluation could at best tie (on two
// cores with one kept busy: 0.195 against 0.194 ms on the measured beam)
// while its workers' waking and spinning cost the run around it. The trial
// is then put off, and the wait doubled as after a trial lost.
#ifndef DWELLFIT_ESTIMATOR_FIT_THREAD_CHOICE_H_
#define DWELLFIT_ESTIMATOR_FIT_THREAD_CHOICE_H_

#include <array>
#include <atomic>

namespace dwellfit {

// The processors of this machine that nothing runs on just now, besides the
// one the caller runs on: the online processors less the tasks the kernel
// counts runnable (/proc/loadavg, the caller among them). -1 where the count
// cannot be read. Machine-wide: in a container the count is the host's. A
// worker of this process still looking for work before it sleeps counts as
// busy; the choice reads the probe where its workers have been idle for a
// while (a trial of the threads) or not started (a new history's start).
int IdleProcessors();
// A probe of idle processors (IdleProcessors; tests give their own).
using IdleProbe = int (*)();

struct ThreadChoiceHistory {
  // Histories shared by this process's evaluators of one kind (0 <= kind <
  // kKinds; the dwells' residual kind).
  static constexpr int kKinds = 8;
  static ThreadChoiceHistory& ForKind(int kind);
  // The way the process's choice that recorded last prefers, whatever its
  // kind (0: none has recorded yet, 1: threaded, 2: alone): what the threads
  // last did for this process on this machine. Only the choices of ForKind's
  // histories count.
  static int LastPreferredWay();

  // The way last preferred (0: none yet, 1: threaded, 2: alone), the wait
  // between trials and the evaluations since the last. Relaxed atomics:
  // evaluators on other threads may read and write them at once; a mixed
  // read only moves a trial.
  std::atomic<int> preferred_way{0};
  std::atomic<int> trial_interval{0};
  std::atomic<int> since_trial{0};
  // Evaluations its choices have timed.
  std::atomic<long> timed{0};
  // One of ForKind's: its choices' ways are the process's (LastPreferredWay).
  bool shared = false;
};

class ThreadChoice {
 public:
  static constexpr double kThreadedMargin = 1.3;
  static constexpr int kTrialInterval = 16;
  static constexpr int kMaxTrialInterval = 64;
  static constexpr int kFirstTrialAfter = 3;
  static constexpr int kConfirmations = 3;
  // Evaluations of the preferred way a trial is compared with (their
  // median).
  static constexpr int kTimesCompared = 3;

  // Goes on from `history` (not owned; it must outlive this).
  explicit ThreadChoice(ThreadChoiceHistory* history, IdleProbe idle_probe = &IdleProcessors);

  // Whether the next evaluation runs threaded.
  bool Next();
  // How long [s] the evaluation Next chose took.
  void Record(bool threaded, double seconds);

  bool prefers_threaded() const { return prefer_threaded_; }
  int trial_interval() const { return trial_interval_; }

 private:
  // The wall times of one way's last evaluations.
  struct RecentTimes {
    std::array<double, kTimesCompared> seconds{};
    int count = 0;  // timed so far, at most seconds.size() kept
    void Add(double value) { seconds[count++ % seconds.size()] = value; }
    // The median of the last three, the least of fewer (0: none yet).
    double Typical() const;
  };
  // Whether `seconds` of the way `threaded` beats `other_seconds` of the other.
  static bool Faster(bool threaded, double seconds, double other_seconds);
  void Publish();
  // After a trial lost or put off: twice the wait, 16 to 64 evaluations.
  void LengthenTheWait();
  // Where a new history starts (see the top of the file).
  void StartNewHistory();

  ThreadChoiceHistory* const history_;
  const IdleProbe idle_probe_;
  RecentTimes threaded_times_;
  RecentTimes alone_times_;
  bool prefer_threaded_ = true;
  int trial_interval_ = kFirstTrialAfter;
  int since_trial_ = 0;
  int confirm_left_ = 0;      // evaluations still to confirm a switch
  bool timed_first_ = false;  // the first Record, which is not timed, has come
  bool new_history_ = false;  // nobody had used the history: its start is to come
};

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_FIT_THREAD_CHOICE_H_
