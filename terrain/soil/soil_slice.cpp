#include "terrain/soil/soil_slice.h"

#include <algorithm>
#include <cmath>

namespace drift::soil {

double wedge_weight(double h, double dx, double theta, double gamma) {
  return (h - std::tan(theta) * dx) * dx * gamma / 2.0;  // eq. 2
}

double factor_of_safety(double h, double dx, double theta, double c, double phi, double gamma) {
  const double w = wedge_weight(h, dx, theta, gamma);
  const double l = std::sqrt(dx * dx + std::pow(std::tan(theta) * dx, 2));       // eq. 3
  return (c * l + w * std::cos(theta) * std::tan(phi)) / (w * std::sin(theta));  // eq. 1
}

std::optional<double> failure_plane(double h, double dx, double c, double phi, double gamma) {
  if (!(h > 0) || !(dx > 0)) return std::nullopt;
  const double beta = std::atan(h / dx);
  if (beta <= phi) return std::nullopt;
  const double q = std::cos(beta - phi) + 4.0 * c * std::cos(phi) * std::cos(beta) / (gamma * dx);
  if (q >= 1.0) return std::nullopt;
  const double theta = 0.5 * (beta + phi - std::acos(q));
  if (theta < 0 || theta >= beta) return std::nullopt;
  return theta;
}

double rest_angle(double height, double c, double phi, double gamma) {
  if (!(c > 0)) return phi;
  if (!(height > 0)) return M_PI / 2;
  const double k = 4.0 * c * std::cos(phi) / (gamma * height);
  const double a = std::cos(phi), b = std::sin(phi) + k;
  const double r = std::hypot(a, b);
  return std::min(M_PI / 2, std::atan2(b, a) + std::acos(std::min(1.0, 1.0 / r)));
}

double net_force(double h, double dx, double theta, double gamma) {
  const double t = std::tan(theta) * dx;  // eq. 8
  return gamma * dx * dx / 4.0 * std::log((h * h + dx * dx) / (t * t + dx * dx)) * std::cos(theta) +
         gamma * dx / 2.0 * (h - t - dx * (std::atan(h / dx) - theta)) * std::sin(theta);
}

double transferred_height(double h, double dx, double theta, double v, double dt) {
  return (h - std::tan(theta) * dx) * v * dt / dx;  // eq. 10
}

}  // namespace drift::soil
