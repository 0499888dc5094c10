// `resecto device calibrate`: the paper's laboratory calibration from caliper measurements — the
// sheath's gain and offset by least squares, the loop's 74-point Hall table — with the residuals
// printed, and the calibration file written atomically.
#include <cstdio>
#include <memory>
#include <stdexcept>
#include <string>

#include <nlohmann/json.hpp>

#include "console/commands/command_registry.h"
#include "device/calibration/calibration.h"
#include "device/calibration/calibration_fit.h"

namespace resecto::cli {
namespace {

constexpr const char* kFamilyDescription = "Device tools: list, monitor and calibrate the LP3500 resectoscope interface";

struct CalibrateOptions {
  std::string sheath_csv;
  std::string hall_csv;
  std::string base;
  std::string output;
  bool json = false;
};

template <class T>
T value_or_throw(Result<T> result) {
  if (!result) throw std::runtime_error(result.error());
  return std::move(result).value();
}

void print_residuals(const char* name, const std::vector<device::Residual>& residuals, double rms, double max_abs) {
  std::printf("  %-6s %12s %12s\n", "line", "position_mm", "residual_mm");
  for (const auto& r : residuals) std::printf("  %-6d %12.3f %+12.3f\n", r.line, r.position_mm, r.residual_mm);
  std::printf("  %s residuals: rms %.3f mm, max %.3f mm\n", name, rms, max_abs);
}

nlohmann::json residuals_json(const std::vector<device::Residual>& residuals) {
  nlohmann::json rows = nlohmann::json::array();
  for (const auto& r : residuals) rows.push_back({{"line", r.line}, {"position_mm", r.position_mm}, {"residual_mm", r.residual_mm}});
  return rows;
}

void run_calibrate(const CalibrateOptions& o) {
  if (o.sheath_csv.empty() && o.hall_csv.empty()) throw std::runtime_error("give --sheath, --hall or both");
  device::Calibration calibration =
      o.base.empty() ? device::default_calibration() : value_or_throw(device::read_calibration(o.base));
  nlohmann::json summary;
  if (!o.sheath_csv.empty()) {
    const auto csv = value_or_throw(device::read_numeric_csv(o.sheath_csv));
    const auto fit = value_or_throw(device::fit_sheath(value_or_throw(device::sheath_samples(csv, o.sheath_csv)), o.sheath_csv));
    calibration.sheath_gain_mm_per_count = fit.gain_mm_per_count;
    calibration.sheath_offset_mm = fit.offset_mm;
    calibration.sheath_min_mm = fit.min_mm;
    calibration.sheath_max_mm = fit.max_mm;
    summary["sheath"] = {{"measurements", fit.residuals.size()}, {"gain_mm_per_count", fit.gain_mm_per_count},
                         {"offset_mm", fit.offset_mm}, {"min_mm", fit.min_mm}, {"max_mm", fit.max_mm},
                         {"rms_mm", fit.rms_mm}, {"max_abs_mm", fit.max_abs_mm}, {"residuals", residuals_json(fit.residuals)}};
    if (!o.json) {
      std::printf("sheath: %zu measurements, gain %.6f mm/count, offset %.3f mm, range %.3f to %.3f mm\n",
                  fit.residuals.size(), fit.gain_mm_per_count, fit.offset_mm, fit.min_mm, fit.max_mm);
      print_residuals("sheath", fit.residuals, fit.rms_mm, fit.max_abs_mm);
    }
  }
  if (!o.hall_csv.empty()) {
    const auto csv = value_or_throw(device::read_numeric_csv(o.hall_csv));
    const auto fit = value_or_throw(device::fit_hall_table(value_or_throw(device::hall_samples(csv, o.hall_csv)), o.hall_csv));
    calibration.hall_sum_counts = fit.hall_sum_counts;
    calibration.loop_mm = fit.loop_mm;
    summary["hall"] = {{"measurements", fit.residuals.size()}, {"points", fit.hall_sum_counts.size()},
                       {"rms_mm", fit.rms_mm}, {"max_abs_mm", fit.max_abs_mm}, {"residuals", residuals_json(fit.residuals)}};
    if (!o.json) {
      std::printf("hall: %zu measurements, table of %zu points from %.1f to %.1f mm, Hall sums %u to %u\n",
                  fit.residuals.size(), fit.hall_sum_counts.size(), fit.loop_mm.front(), fit.loop_mm.back(),
                  unsigned{fit.hall_sum_counts.front()}, unsigned{fit.hall_sum_counts.back()});
      print_residuals("hall", fit.residuals, fit.rms_mm, fit.max_abs_mm);
    }
  }
  // The board's own rules decide: what it would refuse is never written.
  if (const auto board = device::to_board(calibration); !board) throw std::runtime_error(board.error());
  if (const auto written = device::write_calibration(calibration, o.output); !written) {
    throw std::runtime_error(written.error());
  }
  summary["output"] = o.output;
  if (o.json) {
    std::printf("%s\n", summary.dump().c_str());
  } else {
    std::printf("wrote %s\n", o.output.c_str());
  }
}

void register_calibrate(CLI::App& app) {
  CLI::App& family = subcommand_family(app, "device", kFamilyDescription);
  auto o = std::make_shared<CalibrateOptions>();
  CLI::App* cmd = family.add_subcommand(
      "calibrate",
      "Fit the sheath's gain/offset and build the loop's Hall table from caliper measurements; write the calibration file");
  cmd->add_option("--sheath", o->sheath_csv, "CSV with columns position_mm,potentiometer_counts")->check(CLI::ExistingFile);
  cmd->add_option("--hall", o->hall_csv,
                  "CSV with columns position_mm,hall_sum_counts (or position_mm,hall_a_counts,hall_b_counts)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--base", o->base, "Start from this calibration file (default: the built-in calibration)")
      ->check(CLI::ExistingFile);
  cmd->add_option("-o,--output", o->output, "Calibration file to write (JSON, replaced atomically)")->required();
  cmd->add_flag("--json", o->json, "Print one JSON object (fits and residuals) instead of the text report");
  cmd->callback([o] { run_calibrate(*o); });
}

}  // namespace

static const RegisterCommand kRegister{"device-calibrate", &register_calibrate};

}  // namespace resecto::cli
