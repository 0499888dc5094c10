// `resecto run`: the simulator. `--headless` drives the core through the emulated device with a
// scripted procedure and writes the JSON report of DESIGN.md's contract.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "console/commands/checked_options.h"
#include "console/commands/command_registry.h"
#include "console/commands/large_model_notice.h"
#include "console/commands/console_command.h"
#include "console/commands/parameter_options.h"
#include "console/headless/headless_run.h"
#include "console/headless/lockstep_device.h"
#include "console/live/interrupt.h"
#include "recordings/recording_writer.h"
#include "rtcore/base/atomic_file.h"
#include "rtcore/base/units.h"
#include "rtcore/mesh/mesh_io.h"

namespace resecto::cli {
namespace {

struct RunOptions {
  bool headless = false;
  std::string procedure = "demo";
  double seconds = 0.0;
  bool realtime = false;
  std::string report;
  std::string trace;
  int trace_events = static_cast<int>(kDefaultTraceEvents);
  std::string record;
  std::string export_surface;
  std::vector<std::string> sets;
  int triangles = 8640;
  int collision_hz = 60;
  int substeps = 16;
  bool inline_collision = false;
  int physics_threads = default_physics_threads();
  bool raw_input = false;
  std::optional<double> contact_reuse_mm;  ///< unset: TissueConfig's
  std::optional<double> contact_margin_mm;  ///< unset: TissueConfig's
  std::int64_t spin_us = kDefaultRealtimeSpinUs;
  std::uint64_t seed = 1;
  std::string calibration;
  bool json = false;
  ConsoleCliOptions console;  ///< without --headless: the console's own options
};

void run(const RunOptions& o) {
  if (!o.headless) {
    // The console with this run's simulation settings (its real-time core is the same as --realtime's).
    ConsoleCliOptions console = o.console;
    console.procedure = o.procedure;
    console.triangles = o.triangles;
    console.sets = o.sets;
    console.collision_hz = o.collision_hz;
    console.substeps = o.substeps;
    console.spin_us = o.spin_us;
    console.physics_threads = o.physics_threads;
    console.seed = o.seed;
    console.calibration = o.calibration;
    console.report = o.report;
    console.trace = o.trace;
    console.trace_events = o.trace_events;
    console.record = o.record;
    open_console(console);
    return;
  }
  HeadlessOptions options;
  Result<Procedure> procedure = find_procedure(o.procedure);
  if (!procedure) throw std::runtime_error(procedure.error());
  if (const std::optional<std::string> note = shadowed_file_note(o.procedure)) std::fprintf(stderr, "%s\n", note->c_str());
  if (Status followed = check_encoder_speeds(*procedure); !followed) throw std::runtime_error(followed.error());
  options.procedure = std::move(*procedure);
  options.seconds = o.seconds;
  options.realtime = o.realtime;
  options.trace_path = o.trace;
  options.trace_events = static_cast<std::uint64_t>(o.trace_events);
  options.record_path = o.record;
  if (!o.export_surface.empty()) {
    // Checked before the run, so a typo does not cost the whole run.
    const std::string extension = lower_extension(o.export_surface);
    if (!is_surface_mesh_extension(extension)) {
      refuse_command_line("--export-surface " + o.export_surface + ": unknown format '" + extension + "' (use .off, .obj, .ply or .stl)");
    }
  }
  options.export_surface_path = o.export_surface;
  // Every output checked before the run (which may take minutes): never a file the run reads, never
  // one path for two outputs, and its folder there.
  const std::vector<std::filesystem::path> inputs{std::filesystem::exists(o.procedure) ? o.procedure : std::string(), o.calibration};
  const std::vector<std::filesystem::path> outputs{o.record, o.report, o.trace, o.export_surface};
  if (Status ok = check_output_paths(outputs, inputs); !ok) throw std::runtime_error(ok.error());
  if (!o.record.empty()) {
    if (Status ok = rec::check_partial_recording_path(o.record, inputs); !ok) throw std::runtime_error(ok.error());
  }
  options.seed = o.seed;
  options.simulation.prostate_triangles = o.triangles;
  options.simulation.collision_hz = o.collision_hz;
  options.simulation.physics_per_collision = o.substeps;
  options.simulation.collision_thread = !o.inline_collision;
  options.simulation.physics_threads = o.physics_threads;
  options.simulation.input_filter.enabled = !o.raw_input;
  if (o.contact_margin_mm) {
    // A margin given alone keeps the default's proportion of reuse shift to margin (0.3 to 1.5 mm):
    // the default 0.3 mm shift would refuse every margin up to it.
    TissueConfig& tissue = options.simulation.tissue;
    const double reuse_per_margin = tissue.contact_reuse_m / tissue.contact_margin_m;
    tissue.contact_margin_m = units::mm_to_m(*o.contact_margin_mm);
    tissue.contact_reuse_m = std::min(tissue.contact_reuse_m, tissue.contact_margin_m * reuse_per_margin);
  }
  if (o.contact_reuse_mm) options.simulation.tissue.contact_reuse_m = units::mm_to_m(*o.contact_reuse_mm);
  if (o.contact_reuse_mm && o.contact_margin_mm && !(*o.contact_reuse_mm < *o.contact_margin_mm)) {
    refuse_command_line("--contact-reuse-mm " + exact_number(*o.contact_reuse_mm) + " must be below --contact-margin-mm " + exact_number(*o.contact_margin_mm));
  }
  options.spin_us = o.spin_us;
  options.simulation.parameters = parameters_from_assignments(o.sets);
  // Options valid alone that do not go together (--contact-reuse-mm past --contact-margin-mm, a
  // --seconds shorter than one collision step at --collision-hz) are refused before the model is built.
  if (Status valid = options.simulation.validate(); !valid) refuse_command_line(valid.error());
  if (o.seconds > 0.0 && !options.simulation.holds_a_collision_step(o.seconds)) {
    // Seconds are rounded to whole ticks: the message gives the ticks too, so a --seconds a little
    // under the step's length (0.0166 at 60 Hz, 16 ticks) is not mistaken for a bound broken.
    char step[96];
    std::snprintf(step, sizeof step, "%d ticks at %.6g Hz, %.6g s", options.simulation.physics_per_collision, 1.0 / options.simulation.tick_s(),
                  options.simulation.tick_s() * options.simulation.physics_per_collision);
    refuse_command_line("--seconds " + exact_number(o.seconds) + ": the run must last at least one collision step, " + step +
                        " (--seconds is rounded to whole ticks)");
  }
  if (!o.calibration.empty()) {
    Result<device::Calibration> calibration = device::read_calibration(o.calibration);
    if (!calibration) throw std::runtime_error(calibration.error());
    options.calibration = *calibration;
  }

  catch_interrupts();
  note_large_model(static_cast<std::size_t>(options.simulation.prostate_triangles), "a gland of");
  Result<HeadlessResult> result = run_headless(options);
  if (!result) throw std::runtime_error(result.error());
  if (!o.report.empty()) {
    if (Status written = write_file_atomically(o.report, result->report.dump(2) + "\n"); !written) {
      throw std::runtime_error(written.error());
    }
  }
  if (o.json) {
    std::printf("%s\n", result->report.dump(2).c_str());
  } else {
    std::fputs(summarize_report(result->report).c_str(), stdout);
  }
  if (result->interrupted_by != 0) {
    char simulated[32];
    std::snprintf(simulated, sizeof simulated, "%.3f", result->report.at("simulated_s").get<double>());
    throw InterruptedRun(result->interrupted_by, "interrupted by " + signal_name(result->interrupted_by) + " after " + simulated +
                                                     " simulated s; every output holds the run up to there");
  }
}

void register_run(CLI::App& app) {
  auto o = std::make_shared<RunOptions>();
  CLI::App* cmd = app.add_subcommand("run", "Run the simulator: the operator console, or with --headless a scripted procedure and its report");
  cmd->add_flag("--headless", o->headless, "No display: drive the core with a procedure and report");
  cmd->add_option("--procedure", o->procedure, "Built-in procedure (demo, turp) or a procedure file")->check(procedure_name_or_file())->capture_default_str();
  cmd->add_option("--seconds", o->seconds, "Simulated seconds (default: the procedure's length)")->check(positive_up_to(86400.0));
  cmd->add_flag("--realtime", o->realtime, "Real time: the device link on its own thread, ticks at their deadlines");
  cmd->add_option("--report", o->report, "Write the JSON report here")->check(nonempty_path());
  cmd->add_option("--trace", o->trace, "Write a Chrome trace-event JSON (opens in Perfetto)")->check(nonempty_path());
  cmd->add_option("--trace-events", o->trace_events,
                  "The trace keeps the run's last N stage timings (32 bytes each in memory, ~6 a tick; the default holds ~13 min at 960 Hz)")
      ->transform(whole_in_range(1000, 1 << 25))
      ->capture_default_str();
  cmd->add_option("--record", o->record, "Record the session to FILE (replay with `resecto replay FILE --verify`)")->check(nonempty_path());
  cmd->add_option("--export-surface", o->export_surface,
                  "At the end, write the remaining tissue's surface at rest, in millimetres (.off, .obj, .ply, .stl)")
      ->check(nonempty_path());
  add_parameter_option(*cmd, o->sets);
  cmd->add_option("--triangles", o->triangles, "Prostate surface triangles")->transform(whole_in_range(200, 1000000))->capture_default_str();
  cmd->add_option("--collision-hz", o->collision_hz, "Collision steps per second")->transform(whole_in_range(10, 1000))->capture_default_str();
  cmd->add_option("--substeps", o->substeps, "Physics steps per collision step")->transform(whole_in_range(1, 64))->capture_default_str();
  cmd->add_flag("--inline-collision", o->inline_collision,
                "Refit and query on the core's own thread instead of the collision thread (same state hashes)");
  cmd->add_option("--physics-threads", o->physics_threads,
                  "Threads sharing each physics step's spring and node loops: 1, or 2 (the core and a helper); same state hashes")
      ->transform(whole_in_range(1, 2))
      ->capture_default_str();
  cmd->add_flag("--raw-input", o->raw_input, "Place the tool by the device's raw readings, without the One Euro smoothing");
  cmd->add_option("--contact-reuse-mm", o->contact_reuse_mm,
                  "Keep the contact candidates, skipping a collision step's refit and search, while the tool and tissue have moved "
                  "at most this far since they were searched (0: search every step; default 0.3, the tool at most a third of it)")
      ->check(finite_range(0.0, 1.5));
  cmd->add_option("--contact-margin-mm", o->contact_margin_mm,
                  "How far outside the tool a point may be and still become a contact candidate; it must exceed what tool and "
                  "tissue move between collision steps (default 1.5)")
      ->check(finite_range(units::m_to_mm(TissueConfig::kMinContactMarginM), units::m_to_mm(TissueConfig::kMaxContactMarginM)));
  cmd->add_option("--spin-us", o->spin_us, "Real time: spin this long before each tick instead of sleeping")
      ->transform(whole_in_range(0, 100000))
      ->capture_default_str();
  cmd->add_option("--calibration", o->calibration, "Device calibration file (default: the reference device's)")->check(existing_path());
  cmd->add_option("--seed", o->seed, "Seed of the emulated sensors' noise")->check(unsigned_64())->capture_default_str();
  cmd->add_flag("--json", o->json, "Print the JSON report instead of the summary");
  add_console_options(*cmd, o->console, true);
  cmd->callback([o, cmd] {
    // The console's own options mean nothing to a headless run (it is driven by its procedure through
    // the emulated device); taking `--device hid` silently would let a user believe hardware drove it.
    if (o->headless) {
      for (const char* console_only : {"--device", "--preset", "--replay", "--actions", "--frames", "--screenshot", "--lockstep", "--insertion-mm",
                                       "--width", "--height", "--slow-frame-ms", "--slow-frame-every", "--view-scale", "--no-vsync"}) {
        if (cmd->count(console_only) > 0) {
          refuse_command_line(std::string(console_only) + " is an option of the operator console; a --headless run follows its procedure through the emulated device");
        }
      }
    } else {
      // And the other way: the console runs until its window closes, in real time, with the core's
      // default contact search and input filter, and writes no surface; taking these
      // silently let a user wait for a file that never came (audit 8, G7).
      for (const char* headless_only : {"--seconds", "--realtime", "--export-surface", "--json", "--inline-collision", "--raw-input",
                                        "--contact-reuse-mm", "--contact-margin-mm"}) {
        if (cmd->count(headless_only) > 0) {
          refuse_command_line(std::string(headless_only) + " is an option of a --headless run; without --headless `resecto run` opens the operator "
                              "console, which runs until its window closes (add --headless, or leave the option out)");
        }
      }
    }
    if (cmd->count("--trace-events") > 0 && o->trace.empty()) refuse_command_line("--trace-events sizes the trace: give --trace FILE too");
    run(*o);
  });
}

const RegisterCommand kRegister{"run", &register_run};

}  // namespace
}  // namespace resecto::cli
