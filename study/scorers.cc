#include "study/scorers.h"

#include <algorithm>
#include <cstdio>
#include <numeric>

#include "core/error.h"
#include "people/random.h"

namespace mmh::study {
namespace {

// Random streams of the scoring phase.
enum Stream : std::uint64_t {
  kDesignStream = 0x64657369676eull,  // "design"
  kViewingStream = 0x76696577ull,     // "view"
  kRankingStream = 0x72616e6bull,     // "rank"
};

void Shuffle(std::vector<int>* values, people::Random* random) {
  // Fisher-Yates with our own uniform index (std::shuffle's use of the engine is unspecified).
  for (int i = static_cast<int>(values->size()) - 1; i > 0; --i) {
    std::swap((*values)[i], (*values)[random->Index(i + 1)]);
  }
}

int EffectiveAnimatorsPerScorer(const ScorerOptions& options, int animators) {
  return std::min(options.animators_per_scorer, animators - 1);
}

std::string Numbered(char prefix, int number) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%c%02d", prefix, number);
  return buffer;
}

}  // namespace

void ScorerOptions::Validate(const std::string& prefix) const {
  if (count < 0) ThrowBadValue(prefix + ".count", std::to_string(count), "0 (the rule) or more");
  if (animators_per_scorer < 1) {
    ThrowBadValue(prefix + ".animators_per_scorer", std::to_string(animators_per_scorer),
                  "at least 1");
  }
  if (comparisons_per_take < 1) {
    ThrowBadValue(prefix + ".comparisons_per_take", std::to_string(comparisons_per_take),
                  "at least 1");
  }
}

int ScorerCount(const ScorerOptions& options, int animators, int takes) {
  options.Validate("scorers");
  if (animators < 2) {
    ThrowBadValue("study.animators", std::to_string(animators),
                  "at least 2 animators (scorers never judge their own work)");
  }
  const int per_scorer = EffectiveAnimatorsPerScorer(options, animators);
  const long total = static_cast<long>(animators) * takes * options.comparisons_per_take;
  const int rule = static_cast<int>((total + per_scorer - 1) / per_scorer);
  const int count = options.count > 0 ? options.count : std::max(rule, animators);
  if (count < animators) {
    ThrowBadValue("scorers.count", std::to_string(count),
                  "at least the number of animators (" + std::to_string(animators) +
                      "), who are scorers too");
  }
  if (static_cast<long>(count) * per_scorer < total) {
    ThrowBadValue("scorers.count", std::to_string(count),
                  "enough scorers for " + std::to_string(total) + " comparisons at " +
                      std::to_string(per_scorer) + " animators each (at least " +
                      std::to_string(rule) + ")");
  }
  // Each (animator, take) needs c distinct scorers, and one animator's K·c comparisons need K·c
  // distinct scorers other than the animator.
  if (count - 1 < takes * options.comparisons_per_take) {
    ThrowBadValue("scorers.count", std::to_string(count),
                  "more than takes x comparisons_per_take = " +
                      std::to_string(takes * options.comparisons_per_take) + " scorers");
  }
  return count;
}

ScoringDesign DrawScoringDesign(const ScorerOptions& options, int animators, int takes,
                                std::uint64_t seed) {
  if (takes < 1) ThrowBadValue("run.takes", std::to_string(takes), "at least 1");
  ScoringDesign design;
  design.animators = animators;
  design.takes = takes;
  design.scorers = ScorerCount(options, animators, takes);
  const int c = options.comparisons_per_take;
  const int block = takes * c;  // one animator's comparisons
  people::Random random(people::DeriveSeed(seed, {kDesignStream}));

  // Slots: the animators in random order, each a block of K·c comparisons with every take c times
  // in random order. Dealing the slots round-robin to the scorers (in random order) gives scorer
  // s the slots s, s + S, s + 2S, ...: a block of K·c <= S consecutive slots never reaches the
  // same scorer twice, so each scorer sees an animator at most once.
  std::vector<int> animator_order(animators);
  std::iota(animator_order.begin(), animator_order.end(), 0);
  Shuffle(&animator_order, &random);
  std::vector<Assignment> slots;
  slots.reserve(static_cast<std::size_t>(animators) * block);
  for (const int animator : animator_order) {
    std::vector<int> take_of(block);
    for (int k = 0; k < block; ++k) take_of[k] = k % takes;
    Shuffle(&take_of, &random);
    for (const int take : take_of) slots.push_back({0, animator, take});
  }
  std::vector<int> scorer_order(design.scorers);
  std::iota(scorer_order.begin(), scorer_order.end(), 0);
  Shuffle(&scorer_order, &random);
  const int total = static_cast<int>(slots.size());
  for (int k = 0; k < total; ++k) slots[k].scorer = scorer_order[k % design.scorers];

  // Scorer s < animators is animator s and must not judge their own work: swap such a slot with
  // another scorer's slot where neither scorer then sees an animator twice or their own work.
  std::vector<std::vector<int>> seen(design.scorers, std::vector<int>(animators, 0));
  for (const auto& slot : slots) ++seen[slot.scorer][slot.animator];
  auto can_take = [&](int scorer, int animator) {
    return scorer != animator && seen[scorer][animator] == 0;
  };
  for (int k = 0; k < total; ++k) {
    Assignment& own = slots[k];
    if (own.scorer != own.animator) continue;
    // Candidates in a random order (deterministic in the seed).
    std::vector<int> candidates(total);
    std::iota(candidates.begin(), candidates.end(), 0);
    Shuffle(&candidates, &random);
    bool swapped = false;
    for (const int j : candidates) {
      Assignment& other = slots[j];
      if (other.animator == own.animator || other.scorer == own.scorer) continue;
      const int s = own.scorer, t = other.scorer;
      // After the swap s sees other.animator and t sees own.animator.
      --seen[s][own.animator];
      --seen[t][other.animator];
      const bool ok = can_take(s, other.animator) && can_take(t, own.animator);
      if (ok) {
        ++seen[s][other.animator];
        ++seen[t][own.animator];
        std::swap(own.scorer, other.scorer);
        swapped = true;
        break;
      }
      ++seen[s][own.animator];
      ++seen[t][other.animator];
    }
    if (!swapped) {
      throw InputError("scorers: no design found for " + std::to_string(animators) +
                       " animators and " + std::to_string(design.scorers) +
                       " scorers without a scorer judging their own work; add scorers "
                       "(scorers.count)");
    }
  }
  std::stable_sort(slots.begin(), slots.end(), [](const Assignment& a, const Assignment& b) {
    return a.scorer != b.scorer ? a.scorer < b.scorer : a.animator < b.animator;
  });
  design.comparisons = std::move(slots);
  return design;
}

std::string AnimatorId(int animator) { return Numbered('A', animator + 1); }

std::string ScorerId(int scorer, int animators) {
  return scorer < animators ? AnimatorId(scorer) : Numbered('S', scorer - animators + 1);
}

std::vector<ComparisonRow> JudgeComparisons(const ScoringDesign& design,
                                            const std::vector<AnimationAppeals>& appeals,
                                            const people::ViewerOptions& viewer, std::uint64_t seed) {
  if (static_cast<int>(appeals.size()) != design.animators) {
    ThrowBadValue("appeals", std::to_string(appeals.size()) + " animators",
                  std::to_string(design.animators) + " as in the design");
  }
  const std::uint64_t viewing_seed = people::DeriveSeed(seed, {kViewingStream});
  std::vector<ComparisonRow> rows;
  rows.reserve(design.comparisons.size());
  for (const Assignment& a : design.comparisons) {
    const AnimationAppeals& animations = appeals[a.animator];
    if (a.take < 0 || a.take >= static_cast<int>(animations.takes.size())) {
      ThrowBadValue("design", "take " + std::to_string(a.take + 1),
                    "one of the animator's " + std::to_string(animations.takes.size()) + " takes");
    }
    const people::Viewer person = people::DrawViewer(viewer, seed, a.scorer);
    // Each viewing has its own noise, keyed by who watches what.
    const auto key = [&](std::uint64_t item) {
      return people::DeriveSeed(viewing_seed, {static_cast<std::uint64_t>(a.scorer),
                                            static_cast<std::uint64_t>(a.animator), item});
    };
    const double montage = people::Utility(animations.montage, person, viewer, seed, key(0));
    const double take = people::Utility(animations.takes[a.take], person, viewer, seed,
                                     key(static_cast<std::uint64_t>(a.take) + 1));
    rows.push_back({ScorerId(a.scorer, design.animators), AnimatorId(a.animator), a.take + 1,
                    montage > take, 0});
  }
  return rows;
}

std::vector<RankingRow> RankOwnAnimations(const std::vector<AnimationAppeals>& appeals,
                                          const people::ViewerOptions& viewer,
                                          const people::SelfAppraisalOptions& self_appraisal,
                                          std::uint64_t seed) {
  const std::uint64_t ranking_seed = people::DeriveSeed(seed, {kRankingStream});
  std::vector<RankingRow> rows;
  for (int i = 0; i < static_cast<int>(appeals.size()); ++i) {
    const people::Viewer person = people::DrawViewer(viewer, seed, i);
    const int takes = static_cast<int>(appeals[i].takes.size());
    // Items: takes 0..K-1, then the montage (K).
    std::vector<double> utility(takes + 1);
    for (int item = 0; item <= takes; ++item) {
      const people::Appeal& appeal = item < takes ? appeals[i].takes[item] : appeals[i].montage;
      utility[item] = people::Utility(
          appeal, person, viewer, seed,
          people::DeriveSeed(ranking_seed,
                          {static_cast<std::uint64_t>(i), static_cast<std::uint64_t>(item)})) +
          people::SelfAppraisalBias(self_appraisal, item, takes);
    }
    std::vector<int> order(takes + 1);
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(),
                     [&](int a, int b) { return utility[a] > utility[b]; });
    std::vector<int> rank(takes + 1);
    for (int r = 0; r <= takes; ++r) rank[order[r]] = r + 1;
    for (int item = 0; item <= takes; ++item) {
      rows.push_back({AnimatorId(i),
                      item < takes ? "take" + std::to_string(item + 1) : std::string(kMontageItem),
                      static_cast<double>(rank[item]), 0});
    }
  }
  return rows;
}

}  // namespace mmh::study
