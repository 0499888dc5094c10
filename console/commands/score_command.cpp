// `resecto score FILE... [--json] [--csv OUT] [--html OUT]` and `resecto score --compare A B --html OUT`:
// scores recordings by re-simulating them through the core (console/score/rescore.h). A recording
// that cannot be scored is reported on standard error, naming why, and skipped; the rest are scored;
// the exit status is 1 when any was skipped.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <set>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "console/commands/checked_options.h"
#include "console/commands/command_registry.h"
#include "console/score/debrief_html.h"
#include "console/score/rescore.h"
#include "rtcore/base/atomic_file.h"

namespace resecto::cli {
namespace {

struct ScoreOptions {
  std::vector<std::string> files;
  std::vector<std::string> compare;
  bool json = false;
  bool quiet = false;
  std::string csv;
  std::string html;
};

void write_or_throw(const std::filesystem::path& path, const std::string& text) {
  if (Status written = write_file_atomically(path, text); !written) throw std::runtime_error(written.error());
}

void score(const ScoreOptions& o) {
  const bool comparing = !o.compare.empty();
  if (comparing && o.compare.size() != 2) refuse_command_line("score --compare takes two recordings (trainee and expert)");
  if (comparing && !o.files.empty()) refuse_command_line("score --compare A B takes no other FILE");
  if (comparing && o.html.empty()) refuse_command_line("score --compare A B needs --html OUT (the side-by-side page)");
  if ((comparing ? o.compare : o.files).empty()) refuse_command_line("score: no recording given (resecto score FILE... or --compare A B)");
  // A recording named twice in a cohort is scored once: twice, it counted twice in the CSV and made
  // two pages of one debrief. A comparison of a recording with itself stays as asked.
  std::vector<std::string> files;
  for (const std::string& file : comparing ? o.compare : o.files) {
    const auto same = [&](const std::string& other) { return names_one_file(other, file); };
    if (!comparing && std::any_of(files.begin(), files.end(), same)) {
      std::fprintf(stderr, "note: %s is given more than once; scored once\n", file.c_str());
      continue;
    }
    files.push_back(file);
  }
  // Several recordings asked for: --html names a folder of pages, however many were distinct.
  const bool cohort = !comparing && o.files.size() > 1;

  // The outputs checked before minutes of re-simulation: never a recording being scored, never the
  // same file twice. With several recordings --html is a folder of pages, made later.
  const std::vector<std::filesystem::path> inputs(files.begin(), files.end());
  const std::vector<std::filesystem::path> outputs{o.csv, !cohort ? o.html : std::string()};
  if (Status ok = check_output_paths(outputs, inputs); !ok) throw std::runtime_error("score: " + ok.error());
  if (cohort && !o.html.empty()) {  // the folder of pages
    if (Status ok = check_output_folder(o.html, "with several recordings --html names a folder of pages"); !ok) throw std::runtime_error("score --html " + ok.error());
  }

  std::vector<RecordingScore> scored;
  nlohmann::ordered_json skipped = nlohmann::ordered_json::array();
  for (std::size_t n = 0; n < files.size(); ++n) {
    const std::string& file = files[n];
    if (!o.quiet) std::fprintf(stderr, "[%zu/%zu] scoring %s\n", n + 1, files.size(), file.c_str());
    int last_percent = 0;
    auto progress = [&](std::uint64_t done, std::uint64_t total) {
      const int percent = total ? static_cast<int>(100 * done / total) : 100;
      if (o.quiet || percent < last_percent + 10) return;
      last_percent = percent - percent % 10;
      std::fprintf(stderr, "  %3d%% (%llu of %llu ticks)\n", percent, static_cast<unsigned long long>(done), static_cast<unsigned long long>(total));
    };
    Result<RecordingScore> result = score_recording(file, progress);
    if (!result) {
      std::fprintf(stderr, "skipped: %s\n", result.error().c_str());
      skipped.push_back({{"file", file}, {"reason", result.error()}});
      continue;
    }
    if (!result->note.empty()) std::fprintf(stderr, "note: %s\n", result->note.c_str());
    scored.push_back(std::move(*result));
  }
  if (comparing && scored.size() != 2) throw std::runtime_error("score --compare: both recordings must score (see above)");

  if (!o.csv.empty()) {
    std::string csv = score_csv_header();
    for (const RecordingScore& s : scored) csv += score_csv_row(s);
    write_or_throw(o.csv, csv);
  }
  if (!o.html.empty()) {
    if (!cohort) {
      if (!scored.empty()) write_or_throw(o.html, debrief_html(scored));
    } else if (!scored.empty()) {
      // Several recordings: OUT is a directory holding one page per recording (none made when every
      // recording was skipped: no empty folders left behind).
      std::error_code error;
      std::filesystem::create_directories(o.html, error);
      if (error) throw std::runtime_error("score --html " + o.html + ": cannot create the directory: " + error.message());
      // A page per recording, named by its file's stem; recordings of one stem from different
      // folders (trainee1/demo.rsrec, trainee2/demo.rsrec) get -2, -3, ... rather than one page each
      // written over the last, and a suffix never takes a name another recording's page has
      // (a/x, b/x and c/x-2 lost b's page to c's, audit 8, G8).
      std::set<std::string> pages;
      for (const RecordingScore& s : scored) {
        const std::string stem = std::filesystem::path(s.file).stem().string();
        std::string page = stem + ".html";
        for (int n = 2; pages.count(page) != 0; ++n) {
          page = stem;
          page.append("-").append(std::to_string(n)).append(".html");  // appended: GCC 12's -O3 -Wrestrict false positive
        }
        pages.insert(page);
        write_or_throw(std::filesystem::path(o.html) / page, debrief_html(std::span<const RecordingScore>(&s, 1)));
      }
    }
  }
  if (o.json) {
    nlohmann::ordered_json out = nlohmann::ordered_json::array();
    for (const RecordingScore& s : scored) {
      out.push_back({{"file", s.file},
                     {"procedure", s.procedure},
                     {"ticks", s.ticks},
                     {"verified_hashes", s.verified_hashes},
                     {"surface_triangles", s.surface_triangles},
                     {"interrupted", s.interrupted.empty() ? nlohmann::ordered_json(nullptr) : nlohmann::ordered_json(s.interrupted)},
                     {"metrics", score_metrics_json(s.score.metrics)}});
    }
    nlohmann::ordered_json doc = {{"scored", out}, {"skipped", skipped}};
    std::printf("%s\n", doc.dump(2).c_str());
  } else {
    for (const RecordingScore& s : scored) {
      const ScoreMetrics& m = s.score.metrics;
      std::printf("%s (%s, %.1f s%s): %.2f g resected (%.2f g adenoma, %.1f%% of it left), %.2f g/min, cuts %llu, perforations %llu, "
                  "sphincter-zone violations %llu, pedal down with nothing cut %.2f s, tool path %.0f mm\n",
                  s.file.c_str(), s.procedure.c_str(), m.procedure_time_s, s.interrupted.empty() ? "" : (", interrupted by " + s.interrupted).c_str(),
                  m.resected_total_g, m.resected_adenoma_g,
                  100.0 * m.remaining_adenoma_fraction, m.grams_per_minute, static_cast<unsigned long long>(m.cuts),
                  static_cast<unsigned long long>(m.perforations), static_cast<unsigned long long>(m.sphincter_zone_violations), m.loop_on_idle_s,
                  m.tool_path_mm);
    }
  }
  if (!skipped.empty()) {
    throw std::runtime_error("score: " + std::to_string(skipped.size()) + " of " + std::to_string(files.size()) + " recordings skipped");
  }
}

void register_score(CLI::App& app) {
  auto o = std::make_shared<ScoreOptions>();
  CLI::App* cmd = app.add_subcommand("score", "Score recordings by re-simulation: metrics, cohort CSV, HTML debrief");
  cmd->add_option("FILE", o->files, "Recordings (from `run --record`)");
  cmd->add_option("--compare", o->compare, "Two recordings side by side (trainee and expert); needs --html")->expected(2);
  cmd->add_flag("--json", o->json, "Print the metrics of every recording (and the skipped ones) as JSON");
  cmd->add_option("--csv", o->csv, "Write one row per recording here (a cohort table)")->check(nonempty_path());
  cmd->add_option("--html", o->html, "Write the debrief page here (a directory of pages when several FILEs are given)")->check(nonempty_path());
  cmd->add_flag("--quiet", o->quiet, "No progress on standard error");
  cmd->callback([o] { score(*o); });
}

const RegisterCommand kRegister{"score", &register_score};

}  // namespace
}  // namespace resecto::cli
