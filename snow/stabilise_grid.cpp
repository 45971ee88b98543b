#include "snow/stabilise_grid.h"

#include <cmath>
#include <numbers>

#include "terrain/error.h"
#include "terrain/slope_relax.h"

namespace drift::snow {

namespace {

terrain::SlopeRule snow_rule(double repose_deg) {
  return {std::tan(repose_deg * std::numbers::pi / 180.0), 0.5, terrain::SlopeShare::HalfSteepest};
}

// Snow depth on the ground: slopes of ground + snow, snow never below 0.
terrain::SlopeCells snow_cells(const terrain::SlopeRule& rule, const terrain::Grid<float>& ground) {
  terrain::SlopeCells cells{{&rule, 1}};
  cells.base = &ground;
  cells.min_value = 0.0;
  return cells;
}

}  // namespace

StabiliseReport stabilise_grid(const terrain::Grid<float>& ground, terrain::Grid<double>& snow,
                               double dx, double dy, const StabiliseOptions& options,
                               const ProgressFn& progress) {
  if (!(options.repose_deg > 0.0 && options.repose_deg < 90.0))
    throw Error("the angle of repose of snow must lie in (0, 90) degrees");
  const terrain::SlopeRule rule = snow_rule(options.repose_deg);
  const terrain::SlopeRelaxOptions o{dx, dy, options.tolerance, options.max_iterations};
  const auto r = terrain::relax_slopes_everywhere(
      snow, snow_cells(rule, ground), o, nullptr, [&](int, double active_share) {
        if (!progress(1.0 - active_share, "stabilising snow")) throw Cancelled();
      });
  progress(1.0, "stabilising snow");
  StabiliseReport report;
  report.iterations = r.passes;
  report.converged = r.converged;
  return report;
}

double max_repose_excess(const terrain::Grid<float>& ground, const terrain::Grid<double>& snow,
                         double dx, double dy, double repose_deg, double min_snow) {
  const terrain::SlopeRule rule = snow_rule(repose_deg);
  return terrain::max_slope_excess(snow, snow_cells(rule, ground), {dx, dy}, {}, min_snow);
}

}  // namespace drift::snow
