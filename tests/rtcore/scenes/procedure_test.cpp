// Procedure files: the built-in demo, interpolation between keyframes, and errors naming the line.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <vector>

#include "rtcore/scenes/procedure.h"

namespace resecto {
namespace {

TEST(Procedure, DemoIsBuiltInAndWellFormed) {
  Result<Procedure> demo = find_procedure("demo");
  ASSERT_TRUE(demo) << demo.error();
  EXPECT_DOUBLE_EQ(demo->duration_s(), 10.0);
  bool cuts = false;
  double deepest = 0.0;
  for (const ProcedureKeyframe& k : demo->keyframes) {
    cuts = cuts || k.cut;
    deepest = std::max(deepest, k.insertion_mm);
  }
  EXPECT_TRUE(cuts);
  EXPECT_GT(deepest, 150.0);  // past the apex (insertion 150 mm with the default registration)
  EXPECT_LT(deepest, 191.5);  // short of the bladder neck
}

TEST(Procedure, TurpMovesAtAHandsPaceBetweenStrokes) {
  // Its moves once rolled up to 135 degrees in 0.2 s and sent the loop out at 115 mm/s: faster than
  // the contact search's margin covers (2,445 ticks outran it, up to 3.79 mm from the searched pose).
  Result<Procedure> turp = find_procedure("turp");
  ASSERT_TRUE(turp) << turp.error();
  const std::vector<ProcedureKeyframe>& keys = turp->keyframes;
  ASSERT_GT(keys.size(), 100u);
  for (std::size_t i = 1; i < keys.size(); ++i) {
    const ProcedureKeyframe &a = keys[i - 1], &b = keys[i];
    const double dt = b.time_s - a.time_s;
    ASSERT_GT(dt, 0.0) << "keyframe " << i;
    EXPECT_LE(std::abs(b.roll_deg - a.roll_deg) / dt, 60.0 + 1e-9) << "keyframe " << i;
    EXPECT_LE(std::abs(b.yaw_deg - a.yaw_deg) / dt, 3.0 + 1e-9) << "keyframe " << i;
    EXPECT_LE(std::abs(b.pitch_deg - a.pitch_deg) / dt, 3.0 + 1e-9) << "keyframe " << i;
    // The loop goes out and back at most 40 mm/s with the pedal up; the cut draws it at 22 mm/s.
    EXPECT_LE(std::abs(b.loop_mm - a.loop_mm) / dt, 40.0 + 1e-9) << "keyframe " << i;
  }
}

TEST(Procedure, JointsInterpolateAndPedalsHold) {
  Result<Procedure> p = parse_procedure("0 0 0 0 100 0 0 0\n2 2 -4 90 140 10 1 0\n4 2 -4 90 140 10 0 1\n", "test");
  ASSERT_TRUE(p) << p.error();
  const ProcedureKeyframe mid = p->sample(1.0);
  EXPECT_DOUBLE_EQ(mid.yaw_deg, 1.0);
  EXPECT_DOUBLE_EQ(mid.pitch_deg, -2.0);
  EXPECT_DOUBLE_EQ(mid.roll_deg, 45.0);
  EXPECT_DOUBLE_EQ(mid.insertion_mm, 120.0);
  EXPECT_DOUBLE_EQ(mid.loop_mm, 5.0);
  EXPECT_FALSE(mid.cut);                 // the pedal goes down at t = 2, not before
  EXPECT_TRUE(p->sample(2.0).cut);
  EXPECT_TRUE(p->sample(3.9).cut);
  EXPECT_TRUE(p->sample(4.0).coagulate);
  EXPECT_DOUBLE_EQ(p->sample(-1.0).insertion_mm, 100.0);  // held before the first keyframe
  EXPECT_DOUBLE_EQ(p->sample(99.0).insertion_mm, 140.0);  // and after the last
}

TEST(Procedure, ErrorsNameTheLineAndColumn) {
  auto error_of = [](const std::string& text) {
    Result<Procedure> p = parse_procedure(text, "mine.txt");
    return p ? std::string() : p.error();
  };
  EXPECT_EQ(error_of("# header\n0 0 0 0 100 0 0 0\n1 0 0 0 100 0\n").rfind("mine.txt:3:14: expected 8 columns", 0), 0u);
  EXPECT_NE(error_of("0 0 0 0 100 0 0 0\n0 0 0 0 100 0 0 0\n").find("mine.txt:2:1: time_s must increase"), std::string::npos);
  EXPECT_NE(error_of("0 0 0 0 300 0 0 0\n").find("mine.txt:1:9: insertion_mm 300 is outside [0, 230]"), std::string::npos);
  EXPECT_NE(error_of("0 0 0 0 100 0 2 0\n").find("mine.txt:1:15: cut must be 0 or 1"), std::string::npos);
  EXPECT_NE(error_of("0 0 zero 0 100 0 0 0\n").find("mine.txt:1:5: pitch_deg is not a number: 'zero'"), std::string::npos);
  EXPECT_NE(error_of("0 0 0 0 0x10 0 0 0\n").find("insertion_mm is not a number: '0x10'"), std::string::npos);  // decimal only, as the meshes
  // A number past a double's range, or nan, is a number that is not finite, as the docs say (audit 32, F14).
  EXPECT_NE(error_of("0 0 0 0 1e999 0 0 0\n").find("insertion_mm is not a finite number: '1e999'"), std::string::npos);
  EXPECT_NE(error_of("0 nan 0 0 100 0 0 0\n").find("yaw_deg is not a finite number: 'nan'"), std::string::npos);
  EXPECT_NE(error_of("0;0;0;0;100;0;0;0\n").find("found 1 (columns are separated by blanks or commas, not ';')"), std::string::npos);
  // A NUL in a word used to cut the message short at it (audit 24).
  EXPECT_NE(error_of(std::string("0 0 0 0 100 0 0 0\x00x\n", 20)).find("coagulate is not a number: '0\\x00x'"), std::string::npos)
      << error_of(std::string("0 0 0 0 100 0 0 0\x00x\n", 20));
  EXPECT_NE(error_of("0 5 0 0 100 0 0 0\n").find("mine.txt:1:3: the first keyframe must have yaw, pitch and roll 0"), std::string::npos);
  EXPECT_NE(error_of("# nothing\n").find("no keyframes"), std::string::npos);
  EXPECT_EQ(error_of("0 0 0 0 100 0 0 0   # start\n1 0 0 0 120 0 0 0# in\n"), "");  // a comment may end a line
  // Columns count bytes from 1, tabs as one: the word at fault, or the line's end for a missing one.
  EXPECT_NE(error_of("0 0 0 0 100 0 0 0\n1\t0 0 0 100 0 0 0 7\n").find("mine.txt:2:19: more than 8 columns"), std::string::npos)
      << error_of("0 0 0 0 100 0 0 0\n1\t0 0 0 100 0 0 0 7\n");
}

// Audit 6, C: "0.0, 0, 0, ..." was "expected 8 columns ..., found 1"; the pose files took commas, so
// the procedures take them by the same rule (text_words with ","): spaces, tabs and commas separate.
TEST(Procedure, CommasSeparateColumnsAsInPoseFiles) {
  const Result<Procedure> p = parse_procedure("0.0, 0, 0, 0, 125, 0, 0, 0\n1.5,0,0,0,158,2.5,1,0  # a stroke\n", "mine.txt");
  ASSERT_TRUE(p) << p.error();
  ASSERT_EQ(p->keyframes.size(), 2u);
  EXPECT_EQ(p->keyframes[1].loop_mm, 2.5);
  EXPECT_TRUE(p->keyframes[1].cut);
  const Result<Procedure> bad = parse_procedure("0,0,0,0,300,0,0,0\n", "mine.txt");
  ASSERT_FALSE(bad);
  EXPECT_EQ(bad.error(), "mine.txt:1:9: insertion_mm 300 is outside [0, 230]");  // columns still count bytes
}

// Audit 32, F13: a file named demo in the current folder was passed over for the built-in demo silently.
TEST(Procedure, ABuiltInNameThatAFileHereAlsoHasIsNoted) {
  const auto dir = std::filesystem::temp_directory_path() / "resecto_procedure_shadowed";
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "demo") << "0 0 0 0 125 0 0 0\n";
  const auto before = std::filesystem::current_path();
  std::filesystem::current_path(dir);
  const std::optional<std::string> demo = shadowed_file_note("demo"), turp = shadowed_file_note("turp"), file = shadowed_file_note("./demo");
  std::filesystem::current_path(before);
  std::filesystem::remove_all(dir);
  ASSERT_TRUE(demo);
  EXPECT_EQ(*demo, "note: --procedure demo is the built-in procedure; to read the file demo here, write ./demo");
  EXPECT_FALSE(turp) << "no file named turp here";
  EXPECT_FALSE(file) << "a path is read as the file it names";
}

// Audit 6, C: a procedure saved as "Unicode" (UTF-16) was reported as a first word of mojibake.
TEST(Procedure, AUtf16FileIsNamedAsOne) {
  const auto path = std::filesystem::temp_directory_path() / "resecto_procedure_utf16.txt";
  for (const std::string bom : {"\xFF\xFE", "\xFE\xFF", ""}) {
    std::string text = bom;
    for (const char c : std::string("0 0 0 0 125 0 0 0\n")) text += bom == "\xFE\xFF" ? std::string{'\0', c} : std::string{c, '\0'};
    std::ofstream(path, std::ios::binary) << text;
    const Result<Procedure> p = load_procedure(path);
    ASSERT_FALSE(p);
    EXPECT_EQ(p.error(), path.string() + ": is UTF-16, not UTF-8 text; save it as UTF-8");
  }
  std::ofstream(path, std::ios::binary) << "0 0 0 0 125 0 0 0\n1 0 0 0 15" + std::string(1, '\0') + "8 0 0 0\n";
  const Result<Procedure> nul = load_procedure(path);
  std::filesystem::remove(path);
  ASSERT_FALSE(nul);
  EXPECT_EQ(nul.error(), path.string() + ":2:11: a NUL byte, which UTF-8 text never holds");
}

// Lines may end in LF, CR LF or a lone CR (classic Mac OS, some spreadsheets' exports): a CR-only file
// used to read as one line of 8 x N words, "more than 8 columns" (audit 24, F11).
TEST(Procedure, LinesEndInLfCrLfOrCr) {
  for (const char* ending : {"\n", "\r\n", "\r"}) {
    const std::string text = std::string("# t yaw pitch roll insertion loop cut coag") + ending + "0 0 0 0 100 0 0 0" + ending +
                             "1 0 0 0 120 5 1 0" + ending + ending + "2 0 0 0 140 0 0 0";
    const Result<Procedure> p = parse_procedure(text, "mine.txt");
    ASSERT_TRUE(p) << p.error();
    ASSERT_EQ(p->keyframes.size(), 3u);
    EXPECT_DOUBLE_EQ(p->keyframes[2].insertion_mm, 140.0);
    const Result<Procedure> bad = parse_procedure(text + ending + "3 0 0 0 300 0 0 0" + ending, "mine.txt");
    ASSERT_FALSE(bad);
    EXPECT_NE(bad.error().find("mine.txt:6:9: insertion_mm 300"), std::string::npos) << bad.error();
  }
  Result<Procedure> unknown = find_procedure("tour");
  ASSERT_FALSE(unknown);
  EXPECT_NE(unknown.error().find("built-in: demo"), std::string::npos);
  EXPECT_FALSE(find_procedure("/nonexistent/file.txt"));
}

// A name without '/' or '.' is a built-in procedure's; a file of that name in the working folder is
// pointed to (audit 24: "no built-in procedure 'proc'" left the user wondering why the file was ignored).
TEST(Procedure, AnUnknownNameThatIsAFileHereSaysHowToReadIt) {
  const std::filesystem::path here = "procedure_name_hint";
  std::ofstream(here) << "0 0 0 0 100 0 0 0\n1 0 0 0 110 0 0 0\n";
  const Result<Procedure> named = find_procedure(here.string());
  std::filesystem::remove(here);
  ASSERT_FALSE(named);
  EXPECT_NE(named.error().find("no built-in procedure 'procedure_name_hint' (built-in: demo, turp); to read the file procedure_name_hint, write ./procedure_name_hint"),
            std::string::npos)
      << named.error();
  const Result<Procedure> absent = find_procedure("procedure_name_hint");
  ASSERT_FALSE(absent);
  EXPECT_EQ(absent.error().find("to read the file"), std::string::npos) << absent.error();
  std::filesystem::create_directory(here);  // a folder of that name is said to be one (audit 30, F10)
  const Result<Procedure> folder = find_procedure(here.string());
  std::filesystem::remove(here);
  ASSERT_FALSE(folder);
  EXPECT_NE(folder.error().find("; procedure_name_hint here is a folder, not a procedure file"), std::string::npos) << folder.error();
}

}  // namespace
}  // namespace resecto
