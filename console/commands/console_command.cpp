// `resecto console`: the operator console (console/gui/), and the options `resecto run` shares with it.
#include "console/commands/console_command.h"

#include <cstdio>
#include <optional>
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <vector>

#include "console/commands/checked_options.h"
#include "console/commands/command_registry.h"
#include "console/commands/large_model_notice.h"
#include "console/commands/parameter_options.h"
#include "console/gui/console_app.h"
#include "console/gui/tissue_presets.h"
#include "console/headless/headless_run.h"
#include "console/headless/lockstep_device.h"
#include "console/live/interrupt.h"
#include "recordings/recording_writer.h"
#include "rtcore/base/atomic_file.h"

namespace resecto::cli {

void add_console_options(CLI::App& cmd, ConsoleCliOptions& o, bool shared_with_run) {
  if (!shared_with_run) {
    cmd.add_option("--procedure", o.procedure, "Built-in procedure (demo, turp) or a procedure file the emulated device follows")->check(procedure_name_or_file())->capture_default_str();
    cmd.add_option("--triangles", o.triangles, "Prostate surface triangles")->transform(whole_in_range(200, 1000000))->capture_default_str();
    cmd.add_option("--report", o.report, "Write the session's JSON report here when the console closes")->check(nonempty_path());
    CLI::Option* trace = cmd.add_option("--trace", o.trace,
                                        "Write a Chrome trace-event JSON (opens in Perfetto) when the console closes: the core's stages and the "
                                        "console's frames on one clock")
                             ->check(nonempty_path());
    cmd.add_option("--trace-events", o.trace_events,
                   "The trace keeps the session's last N stage timings (32 bytes each in memory, ~6 a tick; the default holds ~13 min at 960 Hz)")
        ->transform(whole_in_range(1000, 33554432))
        ->needs(trace);
    add_parameter_option(cmd, o.sets);
    cmd.add_option("--collision-hz", o.collision_hz, "Collision steps per second")->transform(whole_in_range(10, 1000))->capture_default_str();
    cmd.add_option("--substeps", o.substeps, "Physics steps per collision step")->transform(whole_in_range(1, 64))->capture_default_str();
    cmd.add_option("--spin-us", o.spin_us, "Spin this long before each tick instead of sleeping")->transform(whole_in_range(0, 100000))->capture_default_str();
    cmd.add_option("--physics-threads", o.physics_threads,
                   "Threads sharing each physics step's spring and node loops: 1, or 2 (the core and a helper); same state hashes")
        ->transform(whole_in_range(1, 2))
        ->capture_default_str();
    cmd.add_option("--seed", o.seed, "Seed of the emulated sensors' noise")->check(unsigned_64())->capture_default_str();
    cmd.add_option("--calibration", o.calibration, "Device calibration file (default: the reference device's)")->check(existing_path());
  }
  cmd.add_option("--device", o.device,
                 "emulator: the emulated board follows the procedure; keyboard: you drive it (keys, mouse, gamepad, sliders); "
                 "hid: the LP3500 over USB")
      ->check(CLI::IsMember({"emulator", "keyboard", "hid"}))
      ->capture_default_str();
  cmd.add_option("--preset", o.preset, "Tissue parameter preset (JSON) to start from")->check(existing_path());
  cmd.add_option("--replay", o.replay, "Open this recording in the replay panel and show it in the views")->check(existing_path());
  if (!shared_with_run) cmd.add_option("--record", o.record, "Record the session from its first tick to this file (replayable and verifiable)")->check(nonempty_path());
  cmd.add_option("--actions", o.actions, "Scripted UI actions, one 'frame N VERB ...' per line (docs/commands.md, \"Operator console\")")->check(existing_path());
  CLI::Option* frames = cmd.add_option("--frames", o.frames, "Quit after this many frames")->transform(whole_in_range(1, 100000000));
  cmd.add_option("--screenshot", o.screenshot, "Write a PNG of the whole window after the last of --frames")->needs(frames)->check(nonempty_path());
  cmd.add_flag("--lockstep", o.lockstep,
               "Step the emulated board with the core's ticks (no link thread): the state depends only on the procedure and the commands");
  cmd.add_option("--insertion-mm", o.start_insertion_mm, "--device keyboard: where the sheath starts, mm past the pivot (the apex is at 150)")
      ->check(finite_range(0.0, 230.0))
      ->capture_default_str();
  cmd.add_option("--width", o.width, "Window width, pixels (default 1600, or the screen's work area if narrower)")->transform(whole_in_range(640, 8192));
  cmd.add_option("--height", o.height, "Window height, pixels (default 1000, or the screen's work area if lower)")->transform(whole_in_range(480, 8192));
  cmd.add_option("--slow-frame-ms", o.slow_frame_ms, "Make every frame this much slower (to show the core is never held back)")
      ->check(finite_range(0.0, 10000.0));
  cmd.add_option("--slow-frame-every", o.slow_frame_every,
                 "Slow only every Nth frame, so the report can set the core's misses during slow frames beside those during the others")
      ->transform(whole_in_range(1, 1000))
      ->capture_default_str();
  cmd.add_option("--view-scale", o.view_scale,
                 "Resolution of the 3-D views relative to their panels (default: 1 on a GPU, 0.5 on a software rasteriser)")
      ->check(finite_range(0.1, 2.0));
  cmd.add_flag("--no-vsync", o.no_vsync, "Draw frames as fast as possible instead of at the display's refresh");
}

void open_console(const ConsoleCliOptions& o) {
  if (!gui::display_available()) {
    throw std::runtime_error("no display (neither DISPLAY nor WAYLAND_DISPLAY is set): run the console under X or Wayland, "
                             "or use `resecto run --headless`");
  }
  // Before the window opens: an output that is one of the session's inputs would destroy it, and a
  // folder that is missing or takes no file would lose the session's output only at its end.
  std::vector<std::filesystem::path> inputs{o.actions, o.preset, o.replay, o.calibration};
  if (!names_a_builtin_procedure(o.procedure)) inputs.emplace_back(o.procedure);
  std::erase_if(inputs, [](const std::filesystem::path& p) { return p.empty(); });
  const std::vector<std::filesystem::path> outputs{o.record, o.report, o.screenshot, o.trace};
  if (Status writable = check_output_paths(outputs, inputs); !writable) throw std::runtime_error(writable.error());
  if (!o.record.empty()) {
    if (Status writable = rec::check_partial_recording_path(o.record, inputs); !writable) throw std::runtime_error(writable.error());
  }
  gui::ConsoleOptions options;
  options.input_paths = inputs;
  Result<Procedure> procedure = find_procedure(o.procedure);
  if (!procedure) throw std::runtime_error(procedure.error());
  if (const std::optional<std::string> note = shadowed_file_note(o.procedure)) std::fprintf(stderr, "%s\n", note->c_str());
  options.core.device.source = o.device == "keyboard" ? DeviceSource::kEmulatorManual
                               : o.device == "hid"    ? DeviceSource::kHid
                                                      : DeviceSource::kEmulatorScript;
  if (options.core.device.source == DeviceSource::kEmulatorScript) {
    if (Status followed = check_encoder_speeds(*procedure); !followed) throw std::runtime_error(followed.error());
  }
  options.core.device.procedure = std::move(*procedure);
  options.core.device.manual_start.insertion_mm = o.start_insertion_mm;
  options.core.device.seed = o.seed;
  if (!o.calibration.empty()) {
    Result<device::Calibration> calibration = device::read_calibration(o.calibration);
    if (!calibration) throw std::runtime_error(calibration.error());
    options.core.device.calibration = *calibration;
  }
  options.core.lockstep = o.lockstep;
  options.core.spin_us = o.spin_us;
  options.core.simulation.prostate_triangles = o.triangles;
  options.core.simulation.collision_hz = o.collision_hz;
  options.core.simulation.physics_per_collision = o.substeps;
  options.core.simulation.physics_threads = o.physics_threads;
  // The preset first, then --set over it: a value given on the command line is the one asked for.
  TissueParameters parameters;
  if (!o.preset.empty()) {
    Result<TissueParameters> preset = gui::load_preset(o.preset, parameters);
    if (!preset) throw std::runtime_error(preset.error());
    parameters = *preset;
  }
  parameters = parameters_from_assignments(o.sets, parameters);
  options.settings.parameters = parameters;
  options.settings.window_width = o.width;
  options.settings.window_height = o.height;
  options.actions_path = o.actions;
  options.screenshot_path = o.screenshot;
  options.frames = o.frames;
  options.report_path = o.report;
  options.trace_path = o.trace;
  // Without a trace to write, the ring only keeps the last seconds (nothing reads it).
  if (!o.trace.empty()) options.core.trace_capacity = o.trace_events > 0 ? static_cast<std::size_t>(o.trace_events) : kDefaultTraceEvents;
  options.record_path = o.record;
  options.replay_path = o.replay;
  options.slow_frame_ms = o.slow_frame_ms;
  options.slow_frame_every = o.slow_frame_every;
  options.vsync = !o.no_vsync;
  options.view_scale = o.view_scale;
  catch_interrupts();
  note_large_model(static_cast<std::size_t>(options.core.simulation.prostate_triangles), "a gland of");
  Result<nlohmann::ordered_json> report = gui::run_console(options);
  if (!report) throw std::runtime_error(report.error());
  std::fputs(gui::summarize_console_report(*report).c_str(), stdout);
  if (!o.screenshot.empty()) std::printf("  screenshot       %s\n", o.screenshot.c_str());
  if (const int signal_number = interrupt_signal(); signal_number != 0) {
    throw InterruptedRun(signal_number, "console closed by " + signal_name(signal_number) + "; its recording and report are complete");
  }
}

namespace {

void register_console(CLI::App& app) {
  auto o = std::make_shared<ConsoleCliOptions>();
  CLI::App* cmd = app.add_subcommand("console", "The operator console: endoscopic and outside views, live tissue tuning, profiler");
  add_console_options(*cmd, *o, false);
  cmd->callback([o] { open_console(*o); });
}

const RegisterCommand kRegister{"console", &register_console};

}  // namespace
}  // namespace resecto::cli
