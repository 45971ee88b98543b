// Li & Moshell's slope stability of one soil slice (paper 004, sec. 2.1.2,
// eqs. 1-10, after Li & Moshell 1993). A slice is the soil between two
// neighbouring columns: rise h above the lower column's top, run dx; the
// triangle on top may slide along a failure plane at angle theta.
//
// Units: h, dx in metres; c in t/m; gamma in t/m^2; forces in t (per metre
// of slice width); angles in radians.
#pragma once

#include <optional>

namespace drift::soil {

// Eq. 2: weight of the wedge above the plane at theta.
double wedge_weight(double h, double dx, double theta, double gamma);

// Eq. 1: factor of safety of the plane at theta (shear strength over shear
// stress); < 1 fails.
double factor_of_safety(double h, double dx, double theta, double c, double phi, double gamma);

// Eq. 4 solved for theta in [0, atan(h / dx)]: the failure plane, or nothing
// if the slope is stable (F >= 1 on every plane).
//
// With L = dx / cos(theta) and W from eq. 2, F = 1 reads
//   (h cos(theta) - dx sin(theta)) sin(theta - phi) = 2 c cos(phi) / gamma,
// and with beta = atan(h / dx) the left side is
//   dx / (2 cos(beta)) (cos(beta + phi - 2 theta) - cos(beta - phi)),
// so the planes with F = 1 are theta = (beta + phi -+ acos(q)) / 2,
//   q = cos(beta - phi) + 4 c cos(phi) cos(beta) / (gamma dx).
// F < 1 between them; the lower one bounds the larger sliding wedge and is
// the failure plane. Cohesionless soil (c = 0) fails on theta = phi.
std::optional<double> failure_plane(double h, double dx, double c, double phi, double gamma);

// The steepest angle (radians) at which a slope of real height `height` (m)
// stands: Li & Moshell's failure test (eq. 4) applied to the whole slope,
// a wedge of rise H and run H / tan(beta), rather than to one voxel's step.
// failure_plane(H, H / tan(beta), ...) finds no plane exactly when
//   H <= 4 c / gamma * sin(beta) cos(phi) / (1 - cos(beta - phi))
// (Culmann's critical height; at beta = 90 degrees Terzaghi's
// 4 c / gamma tan(45 + phi / 2)). Solved for beta: with
// k = 4 c cos(phi) / (gamma H), cos(beta) cos(phi) + sin(beta) (sin(phi) + k) = 1,
// beta = atan2(sin(phi) + k, cos(phi)) + acos(1 / R), R the norm of
// (cos(phi), sin(phi) + k). phi for c = 0, pi / 2 once H is below the
// critical height of a vertical cut. In metres, so the same heap settles the
// same at any voxel size (docs/soil.md, Method 6, "Failure in metres").
double rest_angle(double height, double c, double phi, double gamma);

// Eq. 8: net force on the wedge sliding above the plane at theta (Li &
// Moshell's infinitesimal dovetails), t per metre.
double net_force(double h, double dx, double theta, double gamma);

// Eq. 10: height moved from the higher column to the lower one in dt by a
// wedge sliding at v m/s.
double transferred_height(double h, double dx, double theta, double v, double dt);

}  // namespace drift::soil
