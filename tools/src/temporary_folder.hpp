#pragma once
// A fresh folder under the system's temporary directory, removed when done.

#include <filesystem>
#include <string>

namespace adit::tools {

class TemporaryFolder {
 public:
  // `prefix`: the folder's name before mkdtemp's six random characters.
  explicit TemporaryFolder(const std::string& prefix);
  ~TemporaryFolder();
  TemporaryFolder(const TemporaryFolder&) = delete;
  TemporaryFolder& operator=(const TemporaryFolder&) = delete;
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

}  // namespace adit::tools
