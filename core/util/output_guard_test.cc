#include "core/util/output_guard.h"

#include <gtest/gtest.h>

#include <fstream>

#include "core/util/error.h"
#include "tests/support/test_data.h"

namespace pkslam {
namespace {
namespace fs = std::filesystem;

TEST(CheckOutputIsNotInput, RefusesTheInputItselfAndFilesOfAnInputFolder) {
  const fs::path dir = testing::MakeTempDir("output_guard_inputs");
  fs::create_directories(dir / "seq/mav0/cam0/data");
  const fs::path image = dir / "seq/mav0/cam0/data/1.png";
  std::ofstream(image) << "x";
  EXPECT_THROW(CheckOutputIsNotInput(image, "--out", dir / "seq", "--dataset"), OptionError);
  EXPECT_THROW(CheckOutputIsNotInput(dir / "seq", "--out", dir / "seq", "--dataset"), OptionError);
  // Another spelling of the same place.
  EXPECT_THROW(CheckOutputIsNotInput(dir / "seq/mav0/cam0/../cam0/data/1.png", "--out",
                                     dir / "seq", "--dataset"),
               OptionError);
  // New files and folders inside an input folder add to it.
  EXPECT_NO_THROW(CheckOutputIsNotInput(dir / "seq/run", "--out", dir / "seq", "--dataset"));
  EXPECT_NO_THROW(CheckOutputIsNotInput(dir / "seq/cloud.ply", "--out", dir / "seq", "--dataset"));
  // A file input: only the file itself is refused.
  EXPECT_THROW(CheckOutputIsNotInput(image, "--out", image, "--gt"), OptionError);
  EXPECT_NO_THROW(CheckOutputIsNotInput(dir / "seq/mav0/cam0/data/2.png", "--out", image, "--gt"));
  // Beside the input, or a folder whose name merely starts like it: fine.
  EXPECT_NO_THROW(CheckOutputIsNotInput(dir / "run", "--out", dir / "seq", "--dataset"));
  EXPECT_NO_THROW(CheckOutputIsNotInput(dir / "seq2", "--out", dir / "seq", "--dataset"));
  try {
    CheckOutputIsNotInput(image, "--out", dir / "seq", "--dataset");
    ADD_FAILURE() << "no error";
  } catch (const OptionError& e) {
    EXPECT_NE(std::string(e.what()).find("would overwrite a file of the input --dataset"),
              std::string::npos)
        << e.what();
  }
}

TEST(RemoveOwnedDirectory, DeletesOnlyFoldersPkslamMade) {
  const fs::path dir = testing::MakeTempDir("output_guard_owned");
  const fs::path users = dir / "plots";
  fs::create_directories(users);
  std::ofstream(users / "my_figure.pdf") << "x";
  EXPECT_THROW(RemoveOwnedDirectory(users), OptionError);
  EXPECT_TRUE(fs::exists(users / "my_figure.pdf"));
  // A folder made before the marker, recognised by a file only pkslam writes there.
  std::ofstream(users / "index.tsv") << "x";
  EXPECT_NO_THROW(CheckOwnedDirectory(users, "index.tsv"));

  const fs::path ours = dir / "ours";
  CreateOwnedDirectory(ours);
  std::ofstream(ours / "a.png") << "x";
  RemoveOwnedDirectory(ours);
  EXPECT_FALSE(fs::exists(ours));
  EXPECT_NO_THROW(RemoveOwnedDirectory(dir / "absent"));
  fs::create_directories(dir / "empty");
  EXPECT_NO_THROW(RemoveOwnedDirectory(dir / "empty"));
  std::ofstream(dir / "file") << "x";
  EXPECT_THROW(RemoveOwnedDirectory(dir / "file"), OptionError);
}

}  // namespace
}  // namespace pkslam
