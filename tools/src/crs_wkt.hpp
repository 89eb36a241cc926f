#pragma once
// The OGC WKT of a coordinate reference system named by its EPSG code, from
// PROJ's database (libproj, proj-data), for the LAS files of `adit georef`.
// WKT1 as GDAL writes it: LAS 1.4 R15 refers to OGC 01-009 ("Coordinate
// Transformation Services", WKT1) and asks for not the ESRI dialect.

#include <string>

namespace adit::tools {

// Throws adit::InputError naming --epsg when PROJ does not know the code or
// cannot write the CRS as WKT1.
std::string crs_wkt_of_epsg(int code);

}  // namespace adit::tools
