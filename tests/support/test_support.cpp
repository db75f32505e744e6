#include "test_support.hpp"

#include <unistd.h>

#include <gtest/gtest.h>
#include <zlib.h>

#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace cmc33::test {

namespace {

/// One deflate stream of `data`: window_bits 31 for a gzip wrapper, 15 for zlib.
std::string deflate_bytes(const std::string& data, int window_bits)
{
    z_stream z{};
    if (deflateInit2(&z, 6, Z_DEFLATED, window_bits, 8, Z_DEFAULT_STRATEGY) != Z_OK) {
        throw std::runtime_error("deflateInit2 failed");
    }
    std::string out(deflateBound(&z, static_cast<uLong>(data.size())) + 64, '\0');
    z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(data.data()));
    z.avail_in = static_cast<uInt>(data.size());
    z.next_out = reinterpret_cast<Bytef*>(out.data());
    z.avail_out = static_cast<uInt>(out.size());
    const int status = deflate(&z, Z_FINISH);
    out.resize(z.total_out);
    deflateEnd(&z);
    if (status != Z_STREAM_END) throw std::runtime_error("deflate did not finish");
    return out;
}

} // namespace

std::string nifti1_header(const Nifti1Header& header)
{
    const bool single = header.magic == "n+1";
    if (!single && header.magic != "ni1") throw std::invalid_argument("nifti1_header: magic is n+1 or ni1");
    if (header.dims.empty() || header.dims.size() > 7) throw std::invalid_argument("nifti1_header: 1 to 7 dims");
    std::int16_t bitpix = 0;
    switch (header.datatype) { // NIFTI_TYPE_* (nifti1.h) and their sizes in bits
    case 2:
    case 256: bitpix = 8; break;
    case 4:
    case 512: bitpix = 16; break;
    case 8:
    case 16:
    case 768: bitpix = 32; break;
    case 64:
    case 1024:
    case 1280: bitpix = 64; break;
    default: throw std::invalid_argument("nifti1_header: a datatype without a size here");
    }
    std::string bytes(single ? 352 : 348, '\0');
    const auto put = [&](std::size_t offset, auto value) { std::memcpy(bytes.data() + offset, &value, sizeof value); };
    put(0, std::int32_t{348});
    put(40, static_cast<std::int16_t>(header.dims.size()));
    for (std::size_t i = 1; i < 8; ++i) put(40 + 2 * i, i <= header.dims.size() ? header.dims[i - 1] : std::int16_t{1});
    put(70, header.datatype);
    put(72, bitpix);
    for (std::size_t i = 0; i < 4; ++i) put(76 + 4 * i, 1.0f); // pixdim[0] (qfac) to pixdim[3]
    if (single) put(108, 352.0f);                              // vox_offset
    if (header.srow) {
        put(254, std::int16_t{2}); // sform_code
        for (std::size_t r = 0; r < 3; ++r)
            for (std::size_t c = 0; c < 4; ++c) put(280 + 16 * r + 4 * c, (*header.srow)[r][c]);
    }
    std::memcpy(bytes.data() + 344, header.magic.c_str(), 4); // with its terminating zero
    return bytes;
}

std::uint32_t u32_le(const std::string& bytes, std::size_t at)
{
    std::uint32_t v = 0;
    for (std::size_t i = 4; i-- > 0;) v = (v << 8) | static_cast<unsigned char>(bytes.at(at + i));
    return v;
}

std::string gzip_bytes(const std::string& data) { return deflate_bytes(data, 31); }
std::string zlib_bytes(const std::string& data) { return deflate_bytes(data, 15); }

std::filesystem::path run_writer(const std::string& python, const std::string& script, const std::string& name)
{
    const std::filesystem::path dir = std::filesystem::temp_directory_path() / (name + std::to_string(::getpid()));
    std::filesystem::remove_all(dir);
    const std::string command = python + " " + script + " " + dir.string();
    if (std::system(command.c_str()) != 0) return {};
    return dir;
}

std::filesystem::path temp_dir()
{
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    std::string name = info ? std::string(info->test_suite_name()) + "." + info->name() : "no_test";
    for (char& c : name) {
        if (c == '/') c = '_';
    }
    const auto dir = std::filesystem::temp_directory_path() / "cmc33-tests" / name;
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    return dir;
}

const std::vector<VolumeCase>& shared_volume_cases()
{
    static const std::vector<VolumeCase> cases = {
        {"aneurism_256x256x256_uint8.nrrd", 80},  {"bonsai_256x256x256_uint8.nrrd", 40},
        {"engine_256x256x128_uint8.nrrd", 80},    {"tooth_103x94x161_uint8.nrrd", 120},
        {"nucleon_41x41x41_uint8.nrrd", 100},     {"silicium_98x34x34_uint8.nrrd", 100},
        {"CThead_256x256x113_uint16.nrrd", 650},  {"headsq_quarter_64x64x93_uint16.nrrd", 500},
        {"ironProt_68x68x68_uint8.nrrd", 96},     {"neghip_66x66x66_uint8.nrrd", 90},
        {"Bucky_32x32x32_uint8.nrrd", 100},       {"HeadMRVolume_48x62x42_uint8.nrrd", 40},
        {"mri_head_256x256x256_uint8.nrrd", 38},  {"LIDC2_256x256x133_uint8.nrrd", 60},
        {"stent_128x128x256_int16.nrrd", 250},    {"walnut_128x96x114_uint16.nrrd", 5000},
        {"stagbeetle_138x138x82_uint16.nrrd", 900}, {"Cranium_256x256x108_int16.nrrd", 226},
        {"ch2_181x217x181_uint8.nrrd", 30},
    };
    return cases;
}

void PrintTo(const VolumeCase& c, std::ostream* os) { *os << c.file << " at iso " << c.iso; }

std::optional<std::filesystem::path> shared_volume(const std::string& file_name)
{
    const char* shared = std::getenv("CMC33_SHARED");
    if (shared == nullptr) return std::nullopt;
    const auto path = std::filesystem::path(shared) / "data" / "volumes" / file_name;
    if (!std::filesystem::exists(path)) return std::nullopt;
    return path;
}

std::filesystem::path test_data_dir()
{
    const char* dir = std::getenv("CMC33_TEST_DATA");
    return dir ? std::filesystem::path(dir) : std::filesystem::path("tests/data");
}

void write_file(const std::filesystem::path& path, const std::string& bytes)
{
    std::ofstream out(path, std::ios::binary);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

std::string read_file(const std::filesystem::path& path)
{
    std::ifstream in(path, std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

Volume make_volume(Index3 dims, const std::function<double(std::int64_t, std::int64_t, std::int64_t)>& f,
                   Vec3 spacing, Vec3 origin)
{
    Volume v(ScalarType::f64, dims, spacing, origin);
    double* p = v.samples<double>();
    for (std::int64_t k = 0; k < dims[2]; ++k)
        for (std::int64_t j = 0; j < dims[1]; ++j)
            for (std::int64_t i = 0; i < dims[0]; ++i) *p++ = f(i, j, k);
    return v;
}

} // namespace cmc33::test
