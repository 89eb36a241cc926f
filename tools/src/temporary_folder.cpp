// A temporary folder's life (temporary_folder.hpp).
#include "temporary_folder.hpp"

#include <stdlib.h>

#include "adit/common/error.hpp"

namespace adit::tools {

TemporaryFolder::TemporaryFolder(const std::string& prefix) {
  std::string name = (std::filesystem::temp_directory_path() / (prefix + "XXXXXX")).string();
  if (::mkdtemp(name.data()) == nullptr) throw InputError(name, "", "cannot create a temporary folder");
  path_ = name;
}

TemporaryFolder::~TemporaryFolder() {
  std::error_code ec;
  std::filesystem::remove_all(path_, ec);
}

}  // namespace adit::tools
