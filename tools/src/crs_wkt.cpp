#include "crs_wkt.hpp"

#include <memory>

#include <fmt/format.h>
#include <proj.h>

#include "adit/common/error.hpp"

namespace adit::tools {

std::string crs_wkt_of_epsg(int code) {
  const std::unique_ptr<PJ_CONTEXT, decltype(&proj_context_destroy)> ctx(proj_context_create(), proj_context_destroy);
  if (!ctx) throw InputError("--epsg", "", "PROJ could not start (proj_context_create)");
  proj_log_level(ctx.get(), PJ_LOG_NONE);
  const std::string name = std::to_string(code);
  const std::unique_ptr<PJ, decltype(&proj_destroy)> crs(
      proj_create_from_database(ctx.get(), "EPSG", name.c_str(), PJ_CATEGORY_CRS, 0, nullptr), proj_destroy);
  if (!crs) throw InputError("--epsg", "", fmt::format("EPSG:{} is not a coordinate reference system PROJ knows", code));
  const char* const options[] = {"MULTILINE=NO", nullptr};
  const char* wkt = proj_as_wkt(ctx.get(), crs.get(), PJ_WKT1_GDAL, options);
  if (wkt == nullptr) throw InputError("--epsg", "", fmt::format("EPSG:{} cannot be written as OGC WKT1", code));
  return wkt;
}

}  // namespace adit::tools
