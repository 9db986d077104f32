// Phase 2 of the paper's user study ("Comparing animations"), simulated: who compares what, and
// what the simulated viewers (people/viewer.h) prefer.
//
// Design (paper, "Task Design" and "Participants"): S scorers, the first N of them the animators;
// each scorer compares the montage against one take for each of a set of animators
// (animators_per_scorer, never their own); every take of every animator is compared by exactly
// comparisons_per_take scorers. The paper's 20 animators, 3 takes, 42 scorers, 10 animators per
// scorer and 7 comparisons per take give 420 comparisons. For N animators and K takes the number
// of scorers is S = ceil(N·K·c / a) with a = min(animators_per_scorer, N − 1) (the rule that
// keeps c comparisons per take and at most a animators per scorer; 42 for the paper's N = 20);
// when S·a exceeds N·K·c some scorers see one animator fewer.
//
// Each animator ranks their own takes and montage (paper: "we asked them to rank all four
// animations ... that they created").
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "people/self_appraisal.h"
#include "people/viewer.h"
#include "study/study_data.h"

namespace mmh::study {

// Section "scorers".
struct ScorerOptions {
  // Scorers in all (animators included); 0: the rule above (42 for 20 animators and 3 takes).
  int count = 0;
  // Animators whose work each scorer judges (paper: 10); capped at animators − 1.
  int animators_per_scorer = 10;
  // Scorers per (animator, take) (paper: 7).
  int comparisons_per_take = 7;

  template <class V>
  void VisitFields(V& v) {
    v("count", count);
    v("animators_per_scorer", animators_per_scorer);
    v("comparisons_per_take", comparisons_per_take);
  }
  void Validate(const std::string& prefix) const;
};

// The number of scorers for `animators` animators with `takes` takes each (options.count or the
// rule). Throws InputError when the design is impossible (too few scorers for c per take).
int ScorerCount(const ScorerOptions& options, int animators, int takes);

// One comparison of the design: `scorer` watches animator `animator`'s take `take` (0-based) and
// montage.
struct Assignment {
  int scorer = 0;
  int animator = 0;
  int take = 0;
};

struct ScoringDesign {
  int animators = 0;
  int takes = 0;
  int scorers = 0;                      // scorers 0..animators−1 are the animators
  std::vector<Assignment> comparisons;  // sorted by scorer, animator
};

// A random design with the properties above; deterministic in `seed`. Throws InputError when
// the options cannot be met.
ScoringDesign DrawScoringDesign(const ScorerOptions& options, int animators, int takes,
                                std::uint64_t seed);

// IDs as they appear in the CSV files: animator i is "A01", "A02", ... (also their scorer ID, so
// that a self-comparison would show); the other scorers "S01", ...
std::string AnimatorId(int animator);
std::string ScorerId(int scorer, int animators);

// What one animator's animations offer a viewer: takes in recording order, and the montage.
struct AnimationAppeals {
  std::vector<people::Appeal> takes;
  people::Appeal montage;
};

// Each comparison judged by its scorer's simulated viewer (viewer index = scorer index): the
// montage is preferred when its utility in this viewing exceeds the take's. `appeals` has
// design.animators entries. Deterministic in `seed`.
std::vector<ComparisonRow> JudgeComparisons(const ScoringDesign& design,
                                            const std::vector<AnimationAppeals>& appeals,
                                            const people::ViewerOptions& viewer, std::uint64_t seed);

// Each animator ranks their own takes and montage by their utility in one viewing each plus the
// self-appraisal biases (people/self_appraisal.h), 1 = the highest. Same viewers and seed as
// JudgeComparisons.
std::vector<RankingRow> RankOwnAnimations(const std::vector<AnimationAppeals>& appeals,
                                          const people::ViewerOptions& viewer,
                                          const people::SelfAppraisalOptions& self_appraisal,
                                          std::uint64_t seed);

}  // namespace mmh::study
