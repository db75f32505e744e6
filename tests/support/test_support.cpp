#include "test_support.hpp"

#include <gtest/gtest.h>
#include <zlib.h>

#include <cstdlib>
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

std::string gzip_bytes(const std::string& data) { return deflate_bytes(data, 31); }
std::string zlib_bytes(const std::string& data) { return deflate_bytes(data, 15); }

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
