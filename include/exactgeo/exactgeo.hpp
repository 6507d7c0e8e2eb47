// Everything public in one include.
#pragma once

#include "exactgeo/error.hpp"
#include "exactgeo/geodesic.hpp"
#include "exactgeo/io.hpp"
#include "exactgeo/many_sources.hpp"
#include "exactgeo/mesh.hpp"
#include "exactgeo/pairs.hpp"
#include "exactgeo/shapes.hpp"
#include "exactgeo/surface_point.hpp"
#include "exactgeo/value_files.hpp"
#include "exactgeo/version.hpp"
