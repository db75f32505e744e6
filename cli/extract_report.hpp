#pragma once
// What `cmc33 extract` prints, shared by the in-memory run (cmd_extract.cpp) and the run slab by
// slab under --memory-limit (extract_slabs.cpp): one summary line, or one JSON object.

#include <cstdint>
#include <string>
#include <vector>

#include "cmc33/extract.hpp"
#include "cmc33/topology.hpp"
#include "common.hpp"
#include "mesh_steps.hpp"

namespace cmc33::cli {

struct ExtractArgs {
    std::string input;
    double iso = 0;
    std::string output;
    std::string method = "cmc33";
    bool normals = false;
    int threads = 0;
    bool json = false;
    bool ascii = false;
    int repeat = 1;
    bool no_topology = false;
    bool progress = false;
    bool quiet = false;
    std::string memory_limit; ///< empty: the volume and the mesh in memory
    std::string positions = "auto"; ///< auto, float or double (--positions)
    RawVolumeOptions raw;
    MeshSteps steps; ///< --ratio, --smooth and the others of `cmc33 simplify`, after the check
};

struct ExtractReport {
    Json volume;        ///< volume_json() of the input
    Index3 dims{};
    ScalarType type = ScalarType::u8;
    Method method = Method::cmc33;
    std::int64_t vertices = 0, triangles = 0;
    double seconds = 0;                ///< the extraction (in memory) or the whole run (slabs)
    std::vector<double> runs_seconds;
    int threads = 0;
    MeshTopology topology;             ///< when --no-topology is not given
    MeshGeometry geometry;
    bool welded_known = true;          ///< geometry.welded was computed
    ExtractStats stats;
    Json extra = Json::object();       ///< further JSON keys (memory_limit, slabs, simplify)
    std::string steps_text;            ///< the summary line's account of MeshSteps, if any ran
};

/// Prints the summary line or, with --json, the JSON object.
void print_extract_report(const ExtractArgs& args, const ExtractReport& report);

/// `cmc33 extract --memory-limit`: the volume read and the mesh written slab by slab.
void run_extract_slabs(const ExtractArgs& args);


} // namespace cmc33::cli
