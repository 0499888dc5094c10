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

}  // namespace
}  // namespace resecto
