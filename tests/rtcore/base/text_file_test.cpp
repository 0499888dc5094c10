// read_text_file: the bytes of a file exactly (binary-safe), or an error that names the path.
#include "rtcore/base/text_file.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

namespace resecto {
namespace {

std::filesystem::path scratch(const std::string& name) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "resecto_text_file_test";
  std::filesystem::create_directories(dir);
  return dir / name;
}

TEST(ReadTextFile, ReturnsEveryByteUnchanged) {
  const std::string bytes = std::string("line one\r\nline two\n\0binary\xff", 27);
  const std::filesystem::path path = scratch("bytes.txt");
  std::ofstream(path, std::ios::binary) << bytes;
  const Result<std::string> text = read_text_file(path);
  ASSERT_TRUE(text) << text.error();
  EXPECT_EQ(*text, bytes);
}

TEST(ReadTextFile, EmptyFileIsEmptyText) {
  const std::filesystem::path path = scratch("empty.txt");
  std::ofstream(path, std::ios::binary).close();
  const Result<std::string> text = read_text_file(path);
  ASSERT_TRUE(text);
  EXPECT_TRUE(text->empty());
}

TEST(ReadTextFile, MissingFileNamesThePathAndWhatItWas) {
  const std::filesystem::path path = scratch("does_not_exist.json");
  std::filesystem::remove(path);
  const Result<std::string> text = read_text_file(path, " (calibration)");
  ASSERT_FALSE(text);
  EXPECT_EQ(text.error().rfind(path.string() + ": cannot open (calibration)", 0), 0u) << text.error();
}

// Audit 32, F14: a link to nothing was "no such file", though the name is there; a loop says so itself.
TEST(ReadTextFile, ALinkToNothingIsNamedAsOne) {
  const std::filesystem::path loop_a = scratch("loop_a"), loop_b = scratch("loop_b"), dangling = scratch("dangling");
  for (const auto& p : {loop_a, loop_b, dangling}) std::filesystem::remove(p);
  std::filesystem::create_symlink(loop_b, loop_a);
  std::filesystem::create_symlink(loop_a, loop_b);
  std::filesystem::create_symlink(scratch("gone"), dangling);
  const Result<std::string> missing = read_text_file(dangling, " the mesh");
  ASSERT_FALSE(missing);
  EXPECT_EQ(missing.error(), dangling.string() + ": cannot open the mesh: a symbolic link whose target is missing");
  const Result<std::string> loop = read_text_file(loop_a, " the mesh");
  ASSERT_FALSE(loop);
  EXPECT_EQ(loop.error(), loop_a.string() + ": cannot open the mesh: " + std::make_error_code(std::errc::too_many_symbolic_link_levels).message());
  for (const auto& p : {loop_a, loop_b, dangling}) std::filesystem::remove(p);
}

// Audit 6, C: UTF-16 text ("Unicode" in Windows editors) read as a NUL after every character.
TEST(Utf8Text, Utf16AndNulBytesAreNamed) {
  // ASCII as UTF-16 without a byte-order mark: a NUL after (little-endian) or before each character.
  const auto as_utf16 = [](std::string_view ascii, bool little_endian) {
    std::string text;
    for (const char c : ascii) text += little_endian ? std::string{c, '\0'} : std::string{'\0', c};
    return text;
  };
  EXPECT_TRUE(is_utf16("\xFF\xFE"));
  EXPECT_TRUE(is_utf16(as_utf16("0 0 0 1\n", true)));
  EXPECT_TRUE(is_utf16(as_utf16("0 0 0 1\n", false)));
  EXPECT_FALSE(is_utf16(std::string("0 0 0\0 0 0 0", 13)));  // a stray NUL is not UTF-16
  EXPECT_FALSE(is_utf16("0 0 0 0 125 0 0 0\n"));
  EXPECT_EQ(utf8_text_problem("\xFE\xFF" + as_utf16("0", false), "p.txt").value(), "p.txt: is UTF-16, not UTF-8 text; save it as UTF-8");
  EXPECT_EQ(utf8_text_problem(std::string("ab\ncd\0e", 7), "p.txt").value(), "p.txt:2:3: a NUL byte, which UTF-8 text never holds");
  EXPECT_FALSE(utf8_text_problem("\xEF\xBB\xBFok \xC3\xA9\n", "p.txt"));

  const std::filesystem::path path = scratch("utf16.txt");
  std::ofstream(path, std::ios::binary) << std::string("\xFF\xFEo\0k\0", 6);
  const Result<std::string> utf16 = read_utf8_text_file(path, " the procedure file");
  ASSERT_FALSE(utf16);
  EXPECT_EQ(utf16.error(), path.string() + ": is UTF-16, not UTF-8 text; save it as UTF-8");
  std::ofstream(path, std::ios::binary) << "\xEF\xBB\xBFok\n";
  EXPECT_EQ(read_utf8_text_file(path).value(), "ok\n");  // the UTF-8 mark dropped
}

TEST(TextWords, SplitOnBlanksAndTheSeparatorsAsked) {
  const std::vector<TextWord> words = text_words("1.5, 2,,3\t4", ",");
  ASSERT_EQ(words.size(), 4u);
  EXPECT_EQ(words[1].text, "2");
  EXPECT_EQ(words[2].column, 9u);
  EXPECT_EQ(text_words("1.5, 2").size(), 2u);  // without separators, "1.5," is one word
  EXPECT_EQ(text_words("1.5, 2")[0].text, "1.5,");
}

}  // namespace
}  // namespace resecto
