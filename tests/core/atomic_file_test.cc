// Tests of core/atomic_file.h: old content survives a failed write, no temporaries are left.
#include "core/atomic_file.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/error.h"
#include "tests/test_util.h"

namespace mmh {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

using test_util::ReadBytes;
using test_util::ListDir;
using test_util::TempDir;

TEST(AtomicFile, WritesNewFile) {
  TempDir dir;
  WriteFileAtomically(dir / "a.txt", std::string("hello\n"));
  EXPECT_EQ(ReadBytes(dir / "a.txt"), "hello\n");
  EXPECT_EQ(ListDir(dir.path()), std::vector<std::string>{"a.txt"});
}

TEST(AtomicFile, ReplacesExistingFile) {
  TempDir dir;
  WriteFileAtomically(dir / "a.txt", std::string("a much longer old content\n"));
  WriteFileAtomically(dir / "a.txt", [](std::ostream& out) { out << "new"; });
  EXPECT_EQ(ReadBytes(dir / "a.txt"), "new");
  EXPECT_EQ(ListDir(dir.path()), std::vector<std::string>{"a.txt"});
}

TEST(AtomicFile, BinaryContentIsWrittenVerbatim) {
  TempDir dir;
  std::string bytes;
  for (int i = 0; i < 256; ++i) bytes.push_back(static_cast<char>(i));
  bytes += "\r\n\n\r";
  WriteFileAtomically(dir / "b.bin", bytes);
  EXPECT_EQ(ReadBytes(dir / "b.bin"), bytes);
}

TEST(AtomicFile, ThrowingCallbackLeavesOldContentAndNoTemporary) {
  TempDir dir;
  const fs::path path = dir / "keep.txt";
  WriteFileAtomically(path, std::string("old content\n"));
  EXPECT_THROW(WriteFileAtomically(path,
                                   [](std::ostream& out) {
                                     out << "partial new content that must never appear";
                                     out.flush();
                                     throw std::runtime_error("simulated failure");
                                   }),
               std::runtime_error);
  EXPECT_EQ(ReadBytes(path), "old content\n");
  EXPECT_EQ(ListDir(dir.path()), std::vector<std::string>{"keep.txt"});
}

TEST(AtomicFile, ThrowingCallbackPropagatesTheOriginalException) {
  TempDir dir;
  try {
    WriteFileAtomically(dir / "x.txt", [](std::ostream&) { throw InputError("inner problem"); });
    ADD_FAILURE() << "no exception";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "inner problem");
  }
  // Nothing at all was created.
  EXPECT_TRUE(ListDir(dir.path()).empty());
}

TEST(AtomicFile, NonexistentFolderIsAnInputErrorAndCreatesNothing) {
  TempDir dir;
  const fs::path target = dir / "no" / "such" / "file.txt";
  bool called = false;
  try {
    WriteFileAtomically(target, [&](std::ostream&) { called = true; });
    ADD_FAILURE() << "no exception";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr(target.string()));
  }
  EXPECT_FALSE(called);
  EXPECT_TRUE(ListDir(dir.path()).empty());
}

TEST(AtomicFile, TargetThatIsAFolderIsAnInputErrorAndLeavesNoTemporary) {
  TempDir dir;
  fs::create_directory(dir / "taken");
  EXPECT_THROW(WriteFileAtomically(dir / "taken", std::string("x")), InputError);
  EXPECT_TRUE(fs::is_directory(dir / "taken"));
  EXPECT_EQ(ListDir(dir.path()), std::vector<std::string>{"taken"});
}

TEST(AtomicFile, EnsureDirectoryCreatesParents) {
  TempDir dir;
  const fs::path nested = dir / "a" / "b" / "c";
  EnsureDirectory(nested);
  EXPECT_TRUE(fs::is_directory(nested));
  EXPECT_NO_THROW(EnsureDirectory(nested));  // already there
}

TEST(AtomicFile, EnsureDirectoryOverAFileIsAnInputError) {
  TempDir dir;
  WriteFileAtomically(dir / "file", std::string("x"));
  try {
    EnsureDirectory(dir / "file" / "sub");
    ADD_FAILURE() << "no exception";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr((dir / "file" / "sub").string()));
  }
  try {
    EnsureDirectory(dir / "file");
    ADD_FAILURE() << "no exception";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr((dir / "file").string()));
  }
}

}  // namespace
}  // namespace mmh
