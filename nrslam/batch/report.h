// batch: the HTML report of an evaluation — the results table, and per run its RMSE over
// time, its trajectory against the ground truth (top view), and depth-error images of a few
// frames; with sweeps, RMSE against each swept option; deformable runs beside their rigid
// baselines; presets over their scene seeds. One folder, no scripts from the network: it
// opens offline and can be archived with the results.
#pragma once

#include <filesystem>
#include <vector>

#include "nrslam/batch/results.h"
#include "nrslam/batch/rigid_comparison.h"
#include "nrslam/batch/seed_groups.h"

namespace nrslam {

// Writes `folder`/index.html and its images. A run whose folder or sequence cannot be read
// gets a note in the page instead of its plots; the report is still written. `comparisons`
// (CompareWithRigid's, may be empty) get a table of their own, and so do `seed_groups`
// (GroupBySeed's, may be empty).
void WriteReport(const std::vector<RunResult>& results, const std::vector<RigidComparison>& comparisons,
                 const std::vector<SeedGroup>& seed_groups, const std::filesystem::path& folder);

}  // namespace nrslam
