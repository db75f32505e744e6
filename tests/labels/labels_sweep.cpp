// labels_sweep FIELDS [FIRST_SEED [SIGMA]]: the checks of label_checks.cpp on FIELDS random label
// fields of each kind (2, 3, 4 labels; i.i.d. and smooth; 5^3 to 9^3), one line of counts per kind;
// with SIGMA > 0 on the labels smoothed by a Gaussian of SIGMA voxels (LabelOptions::smooth).
// Exit 1 when a guarantee failed.

#include <cstdlib>
#include <iostream>
#include <string>

#include "label_checks.hpp"

int main(int argc, char** argv)
{
    using namespace cmc33::label_checks;
    if (argc < 2) {
        std::cerr << "usage: labels_sweep FIELDS [FIRST_SEED [SIGMA]]\n";
        return 2;
    }
    const long fields = std::strtol(argv[1], nullptr, 10);
    const unsigned long long first = argc > 2 ? std::strtoull(argv[2], nullptr, 10) : 0;
    const double sigma = argc > 3 ? std::strtod(argv[3], nullptr) : 0.0;
    if (!(sigma >= 0) || sigma > 1000) {
        std::cerr << "labels_sweep: SIGMA must be a number of voxels from 0 to 1000, got " << argv[3] << "\n";
        return 2;
    }
    bool ok = true;
    for (const int labels : {2, 3, 4})
        for (const bool smooth : {false, true}) {
            Counts c;
            for (long n = 0; n < fields; ++n) {
                const std::int64_t size = 5 + n % 5;
                const std::uint64_t seed = first + static_cast<std::uint64_t>(n);
                check_field(random_labels(size, labels, seed, smooth), c,
                            std::to_string(labels) + " labels " + (smooth ? "smooth" : "iid") + " seed " +
                                std::to_string(seed),
                            sigma);
            }
            std::cout << labels << " labels " << (smooth ? "smooth" : "iid") << ": fields " << c.fields << " surfaces "
                      << c.label_surfaces << " not_closed " << c.not_closed << " not_manifold " << c.not_manifold
                      << " nonmanifold_edges " << c.nonmanifold_edges << " nonmanifold_vertices "
                      << c.nonmanifold_vertices << " not_oriented " << c.not_oriented << " not_embedded "
                      << c.not_embedded << " union_not_watertight " << c.union_not_watertight << " union_not_embedded "
                      << c.union_not_embedded << " repeated " << c.duplicate_triangles << " two_label_mismatch "
                      << c.two_label_mismatch << " topology_mismatch " << c.topology_mismatch << " two_label_compared "
                      << c.two_label_compared << " euler_mismatch " << c.euler_mismatch << " betti_mismatch "
                      << c.betti_mismatch << " betti_compared " << c.betti_compared
                      << (c.first_failure.empty() ? "" : " first: " + c.first_failure) << std::endl;
            ok = ok && c.not_closed + c.not_oriented + c.not_embedded + c.union_not_watertight + c.union_not_embedded +
                               c.duplicate_triangles + c.two_label_mismatch + c.topology_mismatch + c.not_manifold +
                               c.euler_mismatch + c.betti_mismatch ==
                           0;
        }
    return ok ? 0 : 1;
}
