// The oracles' labelling problem (tests/montage/oracles.h: data[t*m + l], trans[(t*m + l)*m + k])
// as the library's LabellingProblem, for the tests that compare the two.
#pragma once

#include "montage/labelling.h"
#include "tests/montage/oracles.h"

namespace mmh::montage {

inline LabellingProblem ToLabellingProblem(const oracle::Problem& p) {
  LabellingProblem q;
  q.frames = p.n;
  q.takes = p.m;
  q.data = p.data;
  q.transitions.frames = p.n;
  q.transitions.takes = p.m;
  q.transitions.values = p.trans;
  return q;
}

}  // namespace mmh::montage
