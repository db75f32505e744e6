#!/usr/bin/python3
"""Fig. 14 of Custodio et al. 2013 (C13) as numbers: the non-manifold edges of the MC33 methods
(mc33-lewiner, chernyaev: Chernyaev's tubes lie in the face two neighbouring tunnels share, Sec.
5.2) on a skull CT in Hounsfield units (Cranium, 50 isovalues from skin to dense bone) and on
bonsai, with cmc33-paper (C13's cure, Sec. 6.2) and cmc33 beside them. C13 found "one case of
non-manifold edges per 10^7 evaluated voxels"; a case here is a grid face where two tunnels meet,
counted from the mesh (every non-manifold edge lies in such a face: common.shared_faces).

Isovalues are halfway between integers, so no sample equals one (the data are integers).
Writes docs/figures/fig14_nonmanifold.{json,svg,png}.
"""
import os
import sys
import tempfile

import numpy as np

import common

VOLUMES = [
    ("Cranium_256x256x108_int16.nrrd", "Cranium (head CT, HU)", "-899.5:2040.5:60"),  # 50 isovalues
    ("bonsai_256x256x256_uint8.nrrd", "bonsai", "10.5:250.5:2"),  # 121 isovalues
]
METHODS = ["chernyaev", "mc33-lewiner", "cmc33-paper", "cmc33"]
LEGACY = ["chernyaev", "mc33-lewiner"]


def count_cases(path, iso, method, spacing, scratch):
    """Grid faces where two tunnels meet in the method's mesh at iso (one case each)."""
    (positions, triangles), _ = common.extract(path, iso, method, os.path.join(scratch, "m.ply"))
    return len(common.shared_faces(positions, common.nonmanifold_edges(triangles), np.asarray(spacing)))


def main():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out = {"paper_rate_per_1e7_cells": 1.0, "volumes": []}
    fig, axes = plt.subplots(1, len(VOLUMES), figsize=(12, 3.8))
    failed = False
    with tempfile.TemporaryDirectory() as scratch:
        for ax, (name, title, isos) in zip(axes, VOLUMES):
            path = common.volume(name)
            _, spacing = common.read_nrrd(path)
            data = common.sweep(path, isos, METHODS, expected=False)
            cells = data["cells"]
            iso_list = sorted(common.rows_by(data, "cmc33", "b0"))
            entry = {"sweep": data, "cases": {}, "rate_per_1e7_cells": {}, "isosurfaces_with_nonmanifold": {}}
            print(f"{title}: {os.path.basename(path)}, isovalues {isos} ({len(iso_list)}), {cells} cells each")
            for method in METHODS:
                edges = common.rows_by(data, method, "non_manifold_edges")
                cases = {iso: (count_cases(path, iso, method, spacing, scratch) if edges[iso] > 0 else 0) for iso in iso_list}
                total = sum(cases.values())
                rate = total / (cells * len(iso_list)) * 1e7
                with_nm = sum(1 for iso in iso_list if edges[iso] > 0)
                entry["cases"][method] = [cases[i] for i in iso_list]
                entry["rate_per_1e7_cells"][method] = rate
                entry["isosurfaces_with_nonmanifold"][method] = with_nm
                print(f"  {method:>12}: {sum(edges.values())} non-manifold edges in {with_nm} of {len(iso_list)} "
                      f"isosurfaces, {total} cases (faces two tunnels share): {rate:.2f} per 10^7 cells "
                      f"(C13: about 1)")
                if method not in LEGACY and sum(edges.values()) != 0:
                    failed = True
                if method in LEGACY:
                    ax.plot(iso_list, [edges[i] for i in iso_list], marker="o", ms=3, lw=0.8,
                            label=f"{method}: {total} cases, {rate:.2f} / 10^7 cells")
            ax.plot(iso_list, [0] * len(iso_list), color="k", lw=1.2, label="cmc33-paper and cmc33: none")
            ax.set_title(title, fontsize=10)
            ax.set_xlabel("isovalue")
            ax.set_ylabel("non-manifold edges")
            ax.legend(frameon=False, fontsize=8)
            ax.grid(alpha=0.25)
            entry["volume"] = name
            entry["isovalues"] = isos
            out["volumes"].append(entry)
    fig.suptitle("Non-manifold edges of the MC33 methods with Chernyaev's tubes (C13 Sec. 5.2, Fig. 14)", fontsize=10)
    paths = common.save(fig, "fig14_nonmanifold")
    json_path = common.write_json("fig14_nonmanifold", out)
    print("wrote " + ", ".join(common.rel(p) for p in [json_path, *paths]))
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
