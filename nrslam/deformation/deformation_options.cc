#include "nrslam/deformation/deformation_options.h"

#include "nrslam/util/json_options.h"

namespace nrslam {

void DeformationModelOptions::Check() const {
  const std::string context = "deformation";
  CheckOption(k > 0, context, "k must be > 0");
  CheckOption(weighting == "paper" || weighting == "reference", context,
              "weighting must be paper or reference, got '" + weighting + "'");
  CheckOption(sigma_factor > 0, context, "sigma_factor must be > 0");
  CheckOption(max_degree_D >= 1 && max_degree_D <= 100, context, "max_degree_D must be in [1, 100]");
  CheckOption(stretch_threshold > 0, context, "stretch_threshold must be > 0");
  CheckOption(min_edge_weight >= 0 && min_edge_weight < 1, context, "min_edge_weight must be in [0, 1)");
  CheckOption(min_good_edges >= 0, context, "min_good_edges must be >= 0");
  CheckOption(elastic_sigma > 0 && viscous_sigma_factor > 0, context, "regulariser sigmas must be > 0");
  CheckOption(huber_deformation > 0 && huber_reprojection > 0, context, "Huber deltas must be > 0");
  CheckOption(reprojection_sigma_px > 0, context, "reprojection_sigma_px must be > 0");
}

}  // namespace nrslam
