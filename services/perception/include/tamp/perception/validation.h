#pragma once
/// @file
/// Validation of a depth frame before it enters the pipeline. A real driver, a simulator or a
/// malformed DDS message may send anything; the pipeline only sees frames that pass.

#include <cstddef>

#include "tamp/core/error.h"
#include "tamp/core/point_cloud.h"

namespace tamp::perception {

/// Ok, or kInvalidArgument naming the offending field of the frame:
/// - `xyz`: empty, size not a multiple of 3, more than `max_points` points, or a triplet that
///   mixes finite and non-finite values (a no-return is all-NaN or all-infinite);
/// - `width`/`height`: width x height differs from the number of points (width = 0 is allowed
///   and means "unorganised");
/// - `world_T_sensor`: a non-finite translation, or a rotation that is not orthonormal with
///   determinant +1 (tolerance 1e-3).
/// A frame with no valid return at all is accepted (a sensor facing the sky sees nothing).
Status validateFrame(const PointCloudFrame& frame, std::size_t max_points);

}  // namespace tamp::perception
