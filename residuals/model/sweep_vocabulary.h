// The words the model, the data and the fit share about a sweep: which
// control it steps and which way its response jumps at a fold.
#ifndef DWELLFIT_RESIDUALS_MODEL_SWEEP_VOCABULARY_H_
#define DWELLFIT_RESIDUALS_MODEL_SWEEP_VOCABULARY_H_

namespace dwellfit {

// The control a sweep steps: the drive frequency Omega [rad/s] at a fixed
// base level, or the base level a_base at a fixed drive frequency.
enum class SweepKind { kFrequency, kAmplitude };

// A jump, named by the branch that ends at its fold:
//   kJumpUp:   the lower branch ends (a local maximum of G(a));
//   kJumpDown: the upper branch ends (a local minimum of G(a)).
enum class JumpKind { kJumpUp, kJumpDown };

inline const char* SweepKindName(SweepKind kind) {
  return kind == SweepKind::kFrequency ? "frequency" : "amplitude";
}

inline const char* JumpKindName(JumpKind kind) {
  return kind == JumpKind::kJumpUp ? "jump_up" : "jump_down";
}

}  // namespace dwellfit

#endif  // DWELLFIT_RESIDUALS_MODEL_SWEEP_VOCABULARY_H_
