#pragma once
// Internal: samples whose stored type cmc33 does not hold, turned into one it holds, for the readers
// of formats that store them (NIfTI, NumPy .npy): 64-bit integers and half floats widened, and the
// linear rescaling NIfTI's scl_slope/scl_inter asks for. The readers read such samples as a type of
// the same width (so byte order and size checks stay read_samples()'s), then call these.

#include <string>

#include "cmc33/volume.hpp"

namespace cmc33::io::detail {

/// What the stored bytes really are when they differ from the Volume's type.
enum class StoredKind {
    as_is,   ///< the Volume's type
    int64,   ///< read as f64 (8-byte words in the machine's order): signed 64-bit integers
    uint64,  ///< same, unsigned
    float16, ///< read as u16: IEEE 754 binary16
};

/// The samples as cmc33 holds them: int64/uint64 become double (exact up to 2^53 in magnitude,
/// rounded to nearest beyond), float16 become float (exactly). `volume` is consumed.
Volume widen_samples(Volume volume, StoredKind kind);

/// value * slope + inter, computed in double and stored as `type` (float or double), with the
/// frame and metadata of `volume`.
Volume rescale_samples(const Volume& volume, double slope, double inter, ScalarType type, const std::string& label);

} // namespace cmc33::io::detail
