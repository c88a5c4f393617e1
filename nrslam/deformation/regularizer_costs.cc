#include "nrslam/deformation/regularizer_costs.h"

namespace nrslam {

double ElasticMultiplier(const DeformationModelOptions& options, double rest_length) {
  return options.paper_weighting() ? std::sqrt(options.k / rest_length)
                                   : options.k / (rest_length * options.elastic_sigma);
}

double ViscousMultiplier(const DeformationModelOptions& options, double edge_weight_b, double map_scale) {
  return options.paper_weighting() ? std::sqrt(edge_weight_b)
                                   : edge_weight_b / (options.viscous_sigma_factor * map_scale);
}

}  // namespace nrslam
