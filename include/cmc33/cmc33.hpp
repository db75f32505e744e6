#pragma once
/// @file cmc33.hpp
/// Umbrella header of the cmc33 library: every public header (tests/boundaries/umbrella.cmake
/// checks that none is left out).
#include "cmc33/cell.hpp"
#include "cmc33/error.hpp"
#include "cmc33/extract.hpp"
#include "cmc33/io.hpp"
#include "cmc33/labels.hpp"
#include "cmc33/mesh.hpp"
#include "cmc33/mesh_ops.hpp"
#include "cmc33/passes.hpp"
#include "cmc33/sweep.hpp"
#include "cmc33/threads.hpp"
#include "cmc33/topology.hpp"
#include "cmc33/verify.hpp"
#include "cmc33/version.hpp"
#include "cmc33/volume.hpp"
