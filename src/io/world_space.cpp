// Moving a volume's frame between anatomical world spaces (io::convert_space): RAS+ (NIfTI, as
// nibabel's affine gives it) and LPS+ (DICOM, NRRD's usual space) differ by the signs of x and y.

#include <array>
#include <string>
#include <string_view>

#include "cmc33/io.hpp"
#include "volume_formats.hpp"

namespace cmc33::io {
namespace detail {
namespace {

/// The direction letters of a space name ("right-anterior-superior", "RAS", "lps", ...), or "".
std::string letters(std::string_view name)
{
    const std::string lower = lower_ascii(trim(name));
    static constexpr std::array<std::array<std::string_view, 2>, 6> kWords{{{"right", "R"},
                                                                             {"left", "L"},
                                                                             {"anterior", "A"},
                                                                             {"posterior", "P"},
                                                                             {"superior", "S"},
                                                                             {"inferior", "I"}}};
    std::string out;
    if (lower.size() == 3) {
        for (char c : lower) out += static_cast<char>(c - 'a' + 'A');
    } else {
        std::string_view rest = lower;
        while (!rest.empty()) {
            const std::size_t dash = rest.find('-');
            const std::string_view word = rest.substr(0, dash);
            bool known = false;
            for (const auto& w : kWords) {
                if (word == w[0]) out += w[1], known = true;
            }
            if (!known) return "";
            rest = dash == std::string_view::npos ? std::string_view() : rest.substr(dash + 1);
        }
    }
    // one letter per axis: x from R/L, y from A/P, z from S/I
    if (out.size() != 3 || (out[0] != 'R' && out[0] != 'L') || (out[1] != 'A' && out[1] != 'P') ||
        (out[2] != 'S' && out[2] != 'I')) {
        return "";
    }
    return out;
}

std::string long_name(const std::string& l)
{
    std::string out;
    for (char c : l) {
        if (!out.empty()) out += '-';
        out += c == 'R' ? "right" : c == 'L' ? "left" : c == 'A' ? "anterior" : c == 'P' ? "posterior" : c == 'S' ? "superior" : "inferior";
    }
    return out;
}

} // namespace

void convert_space(Vec3& origin, Mat3& direction, std::string& space, std::string_view target, const std::string& label)
{
    const std::string to = letters(target);
    if (to.empty()) {
        throw Error(Status::invalid_argument,
                    str_cat(label, ": unknown space ", quote_bytes(target), "; expected ras or lps"));
    }
    if (space.empty()) {
        throw Error(Status::invalid_argument,
                    str_cat(label, ": the file names no anatomical space (its frame has no orientation), so it cannot be "
                                   "converted to ",
                            long_name(to), "; leave out --space"));
    }
    const std::string from = letters(space);
    if (from.empty()) {
        throw Error(Status::invalid_argument,
                    str_cat(label, ": the file's space ", quote_bytes(space),
                            " is not one of the anatomical spaces (right/left, anterior/posterior, superior/inferior) "
                            "that --space converts"));
    }
    for (std::size_t r = 0; r < 3; ++r) {
        if (from[r] == to[r]) continue;
        origin[r] = -origin[r];
        for (std::size_t c = 0; c < 3; ++c) direction[r][c] = -direction[r][c];
    }
    space = long_name(to);
}

} // namespace detail

void convert_space(Volume& volume, std::string_view space)
{
    Vec3 origin = volume.origin();
    Mat3 direction = volume.direction();
    std::string name = volume.space();
    detail::convert_space(origin, direction, name, space, "volume");
    volume.set_origin(origin);
    volume.set_direction(direction);
    volume.set_space(name);
}

} // namespace cmc33::io
