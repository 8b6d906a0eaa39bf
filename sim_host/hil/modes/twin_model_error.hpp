// The model's error of the twin's story estimates when no baseline was
// commissioned (docs/twin.md section 5): the node identifies the stories
// with the drawing's masses, so a floor's mass off by mu biases the
// stories' estimates by A mu (A = Fkk^-1 Fkm from the outputs' Fisher
// information of the stories' and floors' log factors); with the masses
// within a tolerance (uniform), the bias covariance A A' tol^2 / 3. The
// information is that of a broadband excitation (white ground acceleration),
// not the coming record's: a monitor does not know its earthquake. Measured
// in tools/twin_bound.py's terms, this covariance locates as many losses as
// each record's own (docs/twin.md section 7).
#pragma once

#include <vector>

#include <Eigen/Core>

#include "sim_host/scene/frame.hpp"

namespace vines::host {

// f: the nominal frame; damping_s: stiffness-proportional damping's c_k
// (0: the frame's damping held fixed); sensors: 1-based floors;
// mass_tolerance: each floor's mass within +- this share.
Eigen::MatrixXd mass_effect_covariance(const HostFrame& f, double damping_s, const std::vector<int>& sensors,
                                       double mass_tolerance);

}  // namespace vines::host
