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
// as it is pays for few. A trial of the threads is two threaded evaluations:
// the first wakes the workers and is not timed (after a stretch on the
// caller alone, the first threaded evaluation of `identify` on the beam
// took 1.3-1.6 times as long as the threaded ones after it).
//
// The machine decides which way a trial must beat by a margin. Each trial,
// and a new history's start, asks whether a processor is idle
// (IdleProcessors). With one idle the threads are favoured: the caller alone
// takes over only where it is kThreadedMargin times faster, and the threads
// win back where they are not kThreadedMargin times slower. With none idle
// the other way round: a threaded evaluation then also costs time outside
// itself (the workers that wake, and that look for more work before they
// sleep, take the processor from the caller's serial work), and could at
// best tie (on two cores with one kept busy: 0.195 against 0.194 ms on the
// measured beam). A trial of the threads that falls due with no processor
// idle is therefore put off, and the wait doubled as after a trial lost.
// Favouring the caller alone on an idle machine too, as before, lost the
// threads the beam's vertical stage in a quarter to two fifths of the
// `identify` processes: its first evaluations are dear and drift, and the
// caller alone within 30 % of the threads' cold start took them over (fit
// 45-50 ms against 30 ms).
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
#ifndef DWELLFIT_ESTIMATOR_FIT_THREAD_CHOICE_H_
#define DWELLFIT_ESTIMATOR_FIT_THREAD_CHOICE_H_

#include <array>
#include <atomic>

namespace dwellfit {

// The processors of this machine that no other program runs on just now,
// besides the one the caller runs on: the online processors less one, less
// the tasks the kernel counts runnable (/proc/loadavg) that are not this
// process's threads (/proc/self/task). -1 where the count cannot be read.
// Machine-wide: in a container the count is the host's. This process's own
// threads are left out: its workers still looking for work after a threaded
// evaluation (on two idle cores one was runnable at half of the vertical
// stage's starts on the beam) sleep once the caller goes on alone, and the
// work it runs side by side (the starts of a multi-start, a study's
// replicas) divides the threads among itself beforehand.
int IdleProcessors();
// This process's running or runnable threads (state R in
// /proc/self/task/<tid>/stat), the caller among them; 1 where they cannot be
// read.
int OwnRunnableThreads();
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
  // How many times faster than the favoured way the other must be.
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
  bool Faster(bool threaded, double seconds, double other_seconds) const;
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
  // Whether the margin favours the threads: a processor was idle when the
  // last trial or the history's start asked (or the machine could not say).
  bool favour_threads_ = true;
  // What the last Next chose: the preferred way, a trial, or the threaded
  // evaluation before a trial of the threads that wakes their workers.
  enum class Evaluation { kPreferred, kTrial, kWarmUp };
  Evaluation last_ = Evaluation::kPreferred;
};

}  // namespace dwellfit

#endif  // DWELLFIT_ESTIMATOR_FIT_THREAD_CHOICE_H_
