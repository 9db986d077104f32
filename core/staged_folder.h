// StagedFolder: the all-or-nothing rule every mmh output folder follows (the commands' output
// folders, RGB-D sequences of core/rgbd_folder.h, the fakenect dump of sim/fakenect_writer.h).
// Apart from the image writers so that a program that writes folders but no image (mmh compose)
// links no image library.
#pragma once

#include <filesystem>

namespace mmh {

// An output folder written whole: files go into a staging folder beside the target
// ('<target>.partial-<pid>'); Commit() moves it into place, so readers never see a half-written
// folder, and destruction without Commit() removes the staging folder.
//
// An existing target is replaced only when it is empty or was written by mmh (it holds a marker
// file, camera.json, fakenect.json or run.json, whose "writer" is "mmh"); anything else is an
// InputError naming it, checked when the StagedFolder is made and again in Commit().
class StagedFolder {
 public:
  explicit StagedFolder(const std::filesystem::path& target);
  ~StagedFolder();
  StagedFolder(const StagedFolder&) = delete;
  StagedFolder& operator=(const StagedFolder&) = delete;

  // Moves the staging folder to the target (an old mmh folder there is removed).
  void Commit();

  const std::filesystem::path& target() const { return target_; }
  const std::filesystem::path& staging() const { return staging_; }
  bool committed() const { return committed_; }

 private:
  std::filesystem::path target_;
  std::filesystem::path staging_;
  bool committed_ = false;
};

// The marker files by which an output folder is recognised as mmh's (their "writer" is "mmh").
inline constexpr const char* kMmhMarkerFiles[] = {"camera.json", "fakenect.json", "run.json"};
inline constexpr const char* kMmhWriterName = "mmh";

// "a/b/" names the folder "b": the path without its empty last component, lexically normal.
std::filesystem::path WithoutTrailingSeparator(const std::filesystem::path& path);

}  // namespace mmh
