#!/usr/bin/env bash
# Prints one SHA-256 per mesh of a fixed list of `cmc33 extract` runs: every method (cmc33-paper's
# refinement included), normals on and off, 1 and 2 threads, streaming slabs (--memory-limit), on
# the shared volumes at their README isovalues and on synthetic ones (scripts/make_volume.py), and,
# when the Python package imports, cmc33.marching_cubes' four arrays (the drop-in, values
# included). A refactoring that must not change any mesh runs it with the binary before and after
# and compares the two outputs (diff).
#
#   scripts/mesh-digests.sh CMC33_BINARY [PYTHONPATH_OF_THE_PACKAGE]
#
# Volumes come from $CMC33_VOLUMES (default /work/shared/data/volumes); needs numpy in
# /usr/bin/python3 for the synthetic volumes.
set -euo pipefail
cli=$(realpath "${1:?usage: mesh-digests.sh CMC33_BINARY [PYTHONPATH]}")
pypath=${2:-}
here=$(cd "$(dirname "$0")" && pwd)
vols=${CMC33_VOLUMES:-/work/shared/data/volumes}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

/usr/bin/python3 "$here/make_volume.py" "$tmp/waves64.nrrd" 64 64 64 --periods 3 >/dev/null
/usr/bin/python3 "$here/make_volume.py" "$tmp/waves_odd.nrrd" 131 47 29 --periods 5.5 >/dev/null
/usr/bin/python3 "$here/make_volume.py" "$tmp/waves_flat.nrrd" 300 2 9 --periods 7 >/dev/null

# name, file, isovalue: the README's suggested values (one or two per volume)
cases=(
  "aneurism $vols/aneurism_256x256x256_uint8.nrrd 80"
  "bonsai $vols/bonsai_256x256x256_uint8.nrrd 40"
  "bonsai-pot $vols/bonsai_256x256x256_uint8.nrrd 150"
  "engine $vols/engine_256x256x128_uint8.nrrd 80"
  "tooth $vols/tooth_103x94x161_uint8.nrrd 120"
  "nucleon $vols/nucleon_41x41x41_uint8.nrrd 100"
  "silicium $vols/silicium_98x34x34_uint8.nrrd 110"
  "CThead $vols/CThead_256x256x113_uint16.nrrd 650"
  "CThead-bone $vols/CThead_256x256x113_uint16.nrrd 1500"
  "headsq $vols/headsq_quarter_64x64x93_uint16.nrrd 500"
  "ironProt $vols/ironProt_68x68x68_uint8.nrrd 96"
  "neghip $vols/neghip_66x66x66_uint8.nrrd 90"
  "Bucky $vols/Bucky_32x32x32_uint8.nrrd 51"
  "HeadMR $vols/HeadMRVolume_48x62x42_uint8.nrrd 40"
  "mri_head $vols/mri_head_256x256x256_uint8.nrrd 40"
  "LIDC2 $vols/LIDC2_256x256x133_uint8.nrrd 60"
  "stent $vols/stent_128x128x256_int16.nrrd 250"
  "walnut $vols/walnut_128x96x114_uint16.nrrd 5000"
  "stagbeetle $vols/stagbeetle_138x138x82_uint16.nrrd 800"
  "Cranium $vols/Cranium_256x256x108_int16.nrrd 226"
  "ch2 $vols/ch2_181x217x181_uint8.nrrd 95"
  "waves64 $tmp/waves64.nrrd 128"
  "waves_odd $tmp/waves_odd.nrrd 128"
  "waves_flat $tmp/waves_flat.nrrd 128"
)
small="nucleon silicium headsq ironProt neghip Bucky HeadMR tooth waves64 waves_odd waves_flat"

run() { # label, then extract's arguments; prints "digest label"
  local label=$1
  shift
  "$cli" extract --quiet --no-topology "$@" -o "$tmp/out.ply" >/dev/null
  printf '%s  %s\n' "$(sha256sum <"$tmp/out.ply" | cut -d' ' -f1)" "$label"
}

for c in "${cases[@]}"; do
  read -r name file iso <<<"$c"
  for t in 1 2; do
    run "$name iso=$iso cmc33 threads=$t" "$file" -i "$iso" --threads "$t"
    run "$name iso=$iso cmc33 normals threads=$t" "$file" -i "$iso" --threads "$t" --normals
  done
  methods="cmc33-paper chernyaev mc33-lewiner mc"
  case " $small bonsai CThead " in *" $name "*) ;; *) methods="cmc33-paper mc" ;; esac
  for m in $methods; do
    run "$name iso=$iso $m normals threads=2" "$file" -i "$iso" --method "$m" --threads 2 --normals
    case " $small " in *" $name "*)
      run "$name iso=$iso $m threads=1" "$file" -i "$iso" --method "$m" --threads 1 ;;
    esac
  done
done

# slabs: the volume read and the mesh written within a memory limit (same bytes by design)
for c in "bonsai 40" "CThead 650" "waves64 128" "aneurism 80"; do
  read -r name iso <<<"$c"
  for c2 in "${cases[@]}"; do
    read -r n2 file iso2 <<<"$c2"
    [[ $n2 == "$name" ]] || continue
    run "$name iso=$iso cmc33 normals slabs=8M threads=2" "$file" -i "$iso" --normals --memory-limit 8M --threads 2
    run "$name iso=$iso cmc33 slabs=4M threads=1" "$file" -i "$iso" --memory-limit 4M --threads 1
  done
done

# the Python drop-in (scikit-image's marching_cubes): vertices, faces, normals and values
if [[ -n $pypath ]]; then
  PYTHONPATH=$pypath /usr/bin/python3 - "$tmp" "$vols" <<'EOF'
import hashlib, sys
import numpy as np
import cmc33

tmp, vols = sys.argv[1], sys.argv[2]

def read_nrrd(path):
    import gzip
    raw = open(path, "rb").read()
    head, data = raw.split(b"\n\n", 1)
    fields = dict(l.split(": ", 1) for l in head.decode().splitlines()[1:] if ": " in l)
    sizes = [int(s) for s in fields["sizes"].split()]
    kinds = {"uint8": "u1", "int16": "i2", "uint16": "u2"}
    order = ">" if fields.get("endian") == "big" else "<"
    if fields["encoding"] == "gzip":
        data = gzip.decompress(data)
    return np.frombuffer(data, dtype=order + kinds[fields["type"]]).reshape(sizes[::-1])

for name, file, iso in [("bonsai", "bonsai_256x256x256_uint8.nrrd", 40),
                        ("CThead", "CThead_256x256x113_uint16.nrrd", 650),
                        ("tooth", "tooth_103x94x161_uint8.nrrd", 120),
                        ("nucleon", "nucleon_41x41x41_uint8.nrrd", 100)]:
    vol = read_nrrd(vols + "/" + file)
    for kw in [{}, {"step_size": 1, "allow_degenerate": False}, {"spacing": (2.0, 1.0, 0.5)}]:
        try:
            out = cmc33.marching_cubes(vol, iso, **kw)
        except TypeError:
            continue
        h = hashlib.sha256()
        for a in out:
            h.update(np.ascontiguousarray(a).tobytes())
        print("%s  %s iso=%s python marching_cubes %s" % (h.hexdigest(), name, iso, sorted(kw.items())))
EOF
fi
