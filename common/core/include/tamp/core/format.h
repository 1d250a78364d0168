#pragma once
/// @file
/// Numbers in messages (validation errors, logs): shortest form, `significant` digits (printf %g).

#include <cstdio>
#include <string>

namespace tamp {

/// `v` as printf's "%.<significant>g" (6 = "%g"): 0.5, 1e-09, inf, nan.
inline std::string formatNumber(double v, int significant = 6) {
  char buf[40];
  std::snprintf(buf, sizeof(buf), "%.*g", significant, v);
  return buf;
}

}  // namespace tamp
