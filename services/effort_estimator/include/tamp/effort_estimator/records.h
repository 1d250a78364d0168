#pragma once
/// @file
/// The estimator's view of tamp/effort_model/records.h (the time models live in the leaf library
/// common/effort_model, shared with the simulator and the motion planner): its names are the
/// estimator's too.
#include "tamp/effort_model/records.h"

namespace tamp::effort_estimator {
using namespace tamp::effort_model;  // NOLINT(google-build-using-namespace): one vocabulary
}  // namespace tamp::effort_estimator
