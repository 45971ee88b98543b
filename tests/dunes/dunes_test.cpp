// Sand transport physics: mass conservation, the angle of repose, ripples
// forming from noise with a wavelength set by L0, downwind migration, wind
// direction, tileability and determinism; and the command line.
#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <cmath>
#include <complex>
#include <cstdlib>
#include <filesystem>
#include <numbers>

#include "dunes/avalanche.h"
#include "dunes/sand_model.h"
#include "terrain/error.h"
#include "terrain/raster_io.h"

using namespace drift::dunes;
using drift::terrain::HeightField;
namespace fs = std::filesystem;

namespace {

double total(const HeightField& h) {
  double s = 0;
  for (float v : h.values()) s += v;
  return s;
}

// Mean power spectrum along x (the wind) over all rows; index k = k cycles per row.
std::vector<double> spectrum_along_x(const HeightField& h) {
  const int n = h.width();
  std::vector<double> power(n / 2 + 1, 0.0);
  for (int row = 0; row < h.height(); ++row) {
    double mean = 0;
    for (int x = 0; x < n; ++x) mean += h(x, row);
    mean /= n;
    for (int k = 1; k <= n / 2; ++k) {
      std::complex<double> c = 0;
      for (int x = 0; x < n; ++x)
        c += (h(x, row) - mean) * std::polar(1.0, -2 * std::numbers::pi * k * x / n);
      power[k] += std::norm(c);
    }
  }
  return power;
}

// Wavelength in cells of the strongest component along x (power-weighted
// around the peak, so it is not locked to the integer k).
double dominant_wavelength(const HeightField& h) {
  const auto p = spectrum_along_x(h);
  int best = 1;
  for (int k = 1; k < static_cast<int>(p.size()); ++k)
    if (p[k] > p[best]) best = k;
  double sum = 0, weighted = 0;
  for (int k = std::max(1, best - 2); k <= std::min<int>(p.size() - 1, best + 2); ++k)
    sum += p[k], weighted += p[k] * k;
  return h.width() / (weighted / sum);
}

// The shift along x (cells, wrapped to (-n/2, n/2]) that best aligns b with a.
int best_shift(const HeightField& a, const HeightField& b) {
  const int n = a.width();
  int best = 0;
  double best_c = -1e300;
  for (int s = -n / 2 + 1; s <= n / 2; ++s) {
    double c = 0;
    for (int row = 0; row < a.height(); ++row)
      for (int x = 0; x < n; ++x) c += a(x, row) * b.wrapped(x + s, row);
    if (c > best_c) best_c = c, best = s;
  }
  return best;
}

SandOptions small(Model model, int size, int steps) {
  SandOptions o = default_options(model);
  o.size = size;
  o.steps = steps;
  return o;
}

}  // namespace

TEST(Sand, EveryStepConservesMass) {
  for (Model model : {Model::Ripples, Model::Dunes}) {
    SandOptions o = small(model, 48, 0);
    HeightField h = initial_field(o);
    const double start = total(h);
    double worst = 0;
    for (int s = 0; s < 60; ++s) {
      step(h, o);
      worst = std::max(worst, std::abs(total(h) - start));
    }
    // Float storage: a few ulps per cell of the heights involved.
    EXPECT_LT(worst, 48 * 48 * 1e-5) << "model " << static_cast<int>(model);
  }
}

TEST(Sand, AvalanchingLeavesNoSlopeAboveRepose) {
  SandOptions o = small(Model::Dunes, 48, 0);
  HeightField h(48, 48, 0.0f);
  h(20, 20) = 200.0f;  // a column of sand
  const double start = total(h);
  const double limit = std::tan(34.0 * std::numbers::pi / 180.0) * o.cell_m / o.height_unit;
  avalanche(h, limit, 200000, 1e-5);
  EXPECT_LE(max_excess(h, limit), 1e-4);
  EXPECT_NEAR(total(h), start, 1e-3);
  // And the simulation's result respects the angle of repose too.
  o.steps = 200;
  const HeightField m = run(o);
  EXPECT_LE(max_excess(m, limit), limit * 1e-3 + 1e-6);
}

TEST(Sand, RipplesFormFromNoiseAndTheirWavelengthGrowsWithL0) {
  SandOptions o = small(Model::Ripples, 96, 300);
  const HeightField start = initial_field(o);
  const HeightField ripples = run(o);
  // A dominant wavelength stands out of the spectrum along the wind.
  const auto p = spectrum_along_x(ripples);
  std::vector<double> sorted(p.begin() + 1, p.end());
  std::sort(sorted.begin(), sorted.end());
  EXPECT_GT(sorted.back(), 20 * sorted[sorted.size() / 2]);
  // White noise at the start has no such peak.
  const auto p0 = spectrum_along_x(start);
  std::vector<double> s0(p0.begin() + 1, p0.end());
  std::sort(s0.begin(), s0.end());
  EXPECT_LT(s0.back(), 5 * s0[s0.size() / 2]);
  // Longer flights, longer ripples.
  double previous = 0;
  for (double L0 : {3.0, 5.0, 8.0}) {
    o.L0 = L0;
    const double wavelength = dominant_wavelength(run(o));
    EXPECT_GT(wavelength, previous) << "L0 " << L0;
    EXPECT_GT(wavelength, L0) << "L0 " << L0;  // ripples are longer than a flight
    previous = wavelength;
  }
}

TEST(Sand, DunesMigrateDownwind) {
  SandOptions o = small(Model::Dunes, 64, 1500);
  HeightField h = run(o);
  const HeightField before = h;
  for (int s = 0; s < 100; ++s) step(h, o);
  // Dunes are longer than 100 steps of travel, so the shift is unambiguous.
  EXPECT_GT(best_shift(before, h), 0);
}

TEST(Sand, RipplesWithAWindShadowMigrateDownwind) {
  // Developed ripples of the plain model creep upwind (see the next test);
  // with a 6-degree wind shadow their lee faces catch grains and they move
  // downwind. Measured by the phase of the dominant wave along the wind, step
  // by step (each step moves far less than half a wavelength).
  SandOptions o = small(Model::Ripples, 64, 300);
  o.shadow_deg = 6.0;
  HeightField h = run(o);
  const auto p = spectrum_along_x(h);
  int k = 1;
  for (int i = 1; i < static_cast<int>(p.size()); ++i)
    if (p[i] > p[k]) k = i;
  auto component = [&](const HeightField& f, int row) {
    std::complex<double> c = 0;
    for (int x = 0; x < f.width(); ++x)
      c += static_cast<double>(f(x, row)) * std::polar(1.0, -2 * std::numbers::pi * k * x / 64);
    return c;
  };
  double travelled = 0.0;
  for (int s = 0; s < 20; ++s) {
    const HeightField before = h;
    step(h, o);
    std::complex<double> c = 0;
    for (int row = 0; row < 64; ++row) c += component(h, row) * std::conj(component(before, row));
    travelled += -std::arg(c) * 64 / (2 * std::numbers::pi * k);
  }
  EXPECT_GT(travelled, 0.2);  // cells in 20 steps
}

TEST(Sand, RippleSaltationMovesASmallWaveAsLinearTheoryPredicts) {
  // With L0 = 5.5 cells every grain lands between cells x + 5 and x + 6, so one
  // saltation step maps H to H + q b (H(y - 6) - H(y - 5)) exactly: a wave
  // e^{iky} is multiplied by 1 + q b (e^{-6ik} - e^{-5ik}). Its phase gives the
  // migration per step: downwind for short waves (k L0 just under 2 pi) and
  // upwind for long ones (k L0 under 3 pi / 2), as Nishimori and Ouchi's
  // linear analysis has it. (Developed ripples, about 4/3 L0 long and
  // longer, therefore creep slowly upwind in this model.)
  SandOptions o = small(Model::Ripples, 120, 0);
  o.L0 = 5.5;
  o.b = 2.0;
  o.q = 0.1;
  const int n = 120;
  for (int k_cycles : {20, 13}) {  // wavelengths 6 and 9.2 cells
    const double k = 2 * std::numbers::pi * k_cycles / n;
    HeightField h(n, 4, 0.0f);
    for (int row = 0; row < 4; ++row)
      for (int x = 0; x < n; ++x) h(x, row) = static_cast<float>(1e-3 * std::cos(k * x));
    saltate(h, o);
    std::complex<double> c = 0;
    for (int x = 0; x < n; ++x) c += static_cast<double>(h(x, 0)) * std::polar(1.0, -k * x);
    const std::complex<double> factor =
        1.0 + o.q * o.b * (std::polar(1.0, -6 * k) - std::polar(1.0, -5 * k));
    // Phase of the wave after the step vs theory (the wave had phase 0).
    EXPECT_NEAR(std::arg(c), std::arg(factor), 1e-3) << "wavelength " << n / k_cycles;
    const double shift_cells = -std::arg(c) / k;
    if (k_cycles == 20) {
      EXPECT_GT(shift_cells, 0.0);  // 6 cells: downwind
    } else {
      EXPECT_LT(shift_cells, 0.0);  // 9.2 cells: upwind
    }
  }
}

TEST(Sand, AQuarterTurnOfTheWindTurnsTheField) {
  SandOptions o = small(Model::Ripples, 32, 40);
  o.wind_from_deg = 270.0;  // from the west: crests run north-south
  const HeightField west = simulate(o);
  o.wind_from_deg = 0.0;  // from the north
  const HeightField north = simulate(o);
  const int n = 32;
  // Turning the west-wind field a quarter clockwise gives the north-wind one.
  for (int row = 0; row < n; ++row)
    for (int x = 0; x < n; ++x) ASSERT_EQ(north(n - 1 - row, x), west(x, row)) << x << "," << row;
  // And it is tileable: the step across the wrap is like any other step.
  double wrap = 0, inside = 0;
  for (int row = 0; row < n; ++row) {
    wrap += std::abs(west(0, row) - west(n - 1, row));
    inside += std::abs(west(1, row) - west(0, row));
  }
  EXPECT_LT(wrap, 3 * inside);
}

TEST(Sand, SameBitsForAnyThreadCount) {
  SandOptions o = small(Model::Dunes, 80, 60);
  HeightField reference;
  for (int threads : {1, 2, 4}) {
    tbb::task_arena arena(threads);
    HeightField h;
    arena.execute([&] { h = run(o); });
    if (threads == 1) {
      reference = h;
    } else {
      EXPECT_EQ(h.values(), reference.values()) << threads << " threads";
    }
  }
}

TEST(Sand, BadOptionsAreErrors) {
  SandOptions o;
  o.L0 = 100;
  EXPECT_THROW(validate(o), drift::Error);
  o = default_options(Model::Dunes);
  o.b = o.L0 + 1;
  EXPECT_THROW(validate(o), drift::Error);
  o = default_options(Model::Ripples);
  o.size = 4;
  EXPECT_THROW(validate(o), drift::Error);
}

TEST(DunesCommand, WritesStartSnapshotsAndRefusesNonsense) {
  const fs::path dir = fs::temp_directory_path() / "drift_dunes_cli";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string drift = DRIFT_EXECUTABLE;
  auto run_cli = [&](const std::string& args) {
    return std::system((drift + " dunes " + args + " > /dev/null 2>&1").c_str());
  };
  ASSERT_EQ(run_cli("--size 32 --steps 0 --seed 3 -o " + (dir / "start.tif").string()), 0);
  const HeightField start = drift::terrain::read_raster(dir / "start.tif");
  SandOptions o = default_options(Model::Ripples);
  o.size = 32;
  o.seed = 3;
  const HeightField expected = initial_field(o);
  // The seeded start in metres (wind from the west: no turn).
  EXPECT_FLOAT_EQ(start(5, 7), expected(5, 7) * static_cast<float>(o.height_unit));
  EXPECT_DOUBLE_EQ(start.geo().cell_size_x(), o.cell_m);

  ASSERT_EQ(run_cli("--size 32 --steps 20 --snapshot-every 10 -o " + (dir / "r.tif").string()), 0);
  EXPECT_TRUE(fs::exists(dir / "r_00010.tif"));
  EXPECT_TRUE(fs::exists(dir / "r_00020.tif"));
  EXPECT_TRUE(fs::exists(dir / "r.tif"));

  EXPECT_EQ(run_cli("--model sand -o " + (dir / "x.tif").string()), 2 << 8);
  EXPECT_EQ(run_cli("--size 32 --L0 100 -o " + (dir / "x.tif").string()), 1 << 8);
  EXPECT_FALSE(fs::exists(dir / "x.tif"));
  fs::remove_all(dir);
}
