#pragma once
/// The render job of the model tests' small pictures: the final stage, no progress bar.

#include "model/model.h"

namespace sprig::test {

inline RenderJob finalStageJob(const SpeciesModel& model) {
  RenderJob job;
  job.progress = false;
  job.stage = model.finalStage();
  return job;
}

}  // namespace sprig::test
