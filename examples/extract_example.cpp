// The README's library example: read a volume, extract its isosurface, write it, print its topology.
// Built with the tests and run on the bundled Bucky volume, so the README cannot go stale.
#include <cmc33/cmc33.hpp>
#include <cstdio>
#include <cstdlib>

int main(int argc, char** argv)
{
    if (argc != 4) return std::fprintf(stderr, "usage: %s VOLUME ISO OUT.ply\n", argv[0]), 2;
    char* end = nullptr;
    const double iso = std::strtod(argv[2], &end); // the whole argument, or a usage error naming it
    if (end == argv[2] || *end != '\0') return std::fprintf(stderr, "ISO \"%s\" is not a number\n", argv[2]), 2;
    try {
        const cmc33::Volume volume = cmc33::io::read_volume(argv[1]); // .nrrd .nhdr .mhd .mha .vtk
        const cmc33::Mesh mesh = cmc33::extract(volume, iso);         // method cmc33, all cores
        cmc33::io::write_mesh(mesh, argv[3]);                                // .ply .obj .stl .off
        const cmc33::MeshTopology t = cmc33::mesh_topology(mesh);
        std::printf("%zu triangles, euler %lld, components %lld, non-manifold edges %lld\n", mesh.triangle_count(),
                    static_cast<long long>(t.euler), static_cast<long long>(t.components),
                    static_cast<long long>(t.nonmanifold_edges));
    } catch (const std::exception& e) { // cmc33::Error: one line naming the file and the problem
        return std::fprintf(stderr, "%s\n", e.what()), 1;
    }
}
