#pragma once

#define EXACTGEO_VERSION_MAJOR 0
#define EXACTGEO_VERSION_MINOR 1
#define EXACTGEO_VERSION_PATCH 0

namespace exactgeo {
inline constexpr const char* kVersion = "0.1.0";
}
