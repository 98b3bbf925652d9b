// hairvox bench (private): running one job — the renders of a configuration,
// end to end through renderScene() with real outputs, timed stage by stage
// (median of the runs), and its errors against the scene's references:
//  - image: relative L1 and RMSE of the beauty over hair pixels against the
//    exact reference (film/image_compare.h);
//  - model: the hair's radiance against a path-traced reference, as means
//    over blocks (the model sweep; sweep.h);
//  - probe: MAE of V and T_s (transmittance/probe.h) at points on the fibers
//    toward every lit light, against exact mode with many rays over a disk of
//    the configuration's voxel size. The head is left out of the probe: points
//    it shadows are GlobalTerm::blocked() in every mode and would only dilute it.
#pragma once

#include "job.h"

namespace hairvox::bench {

/// Runs the job in this process and returns what it measured; a reference job
/// also writes the reference image and probe files it names.
BenchMeasurement runJob(const BenchJob& job);

} // namespace hairvox::bench
