// VTK XML PolyData (.vtp), as VTK's "XML File Formats" documentation describes it: file version
// 1.0 with header_type UInt64, every DataArray in the appended section (encoding "raw"), each
// compressed by vtkZLibDataCompressor: a header of UInt64 words [number of blocks, uncompressed
// block size, uncompressed size of the last block (0 when it is whole), compressed size of each
// block], then the zlib streams of the blocks. A DataArray's `offset` counts from the byte after
// the '_' that opens the appended data.
//
// Points are Float32 (Float64 with MeshWriteOptions::offset); polygons are connectivity and
// offsets (the end of each cell in connectivity), Int32 where every value fits, else Int64.
// Point data: Normals (the mesh's, set as the Normals attribute) and the caller's vertex arrays;
// cell data: the caller's triangle arrays.

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <exception>
#include <functional>
#include <limits>
#include <mutex>
#include <ostream>
#include <string>
#include <system_error>
#include <thread>
#include <variant>
#include <vector>

#include "mesh_formats.hpp"
#include "parallel.hpp"

namespace cmc33::io::detail {
namespace {

constexpr std::size_t kBlockBytes = std::size_t{1} << 18; // a multiple of every element size
constexpr int kLevel = 1; // deflate's fastest level: most of its gain on meshes, in a fraction of the time

/// One DataArray: its XML attributes and a source of its little-endian bytes, `size` elements of
/// `element` bytes; fill(dst, first, count) stores elements first .. first + count - 1.
struct Array {
    std::string type; ///< Float32, Float64, Int32, Int64
    std::string name; ///< empty: no Name attribute
    int components = 1;
    std::size_t element = 4;
    std::size_t size = 0;
    std::function<void(char*, std::size_t, std::size_t)> fill;
};

/// The vtkZLibDataCompressor image of an array: header words, then the compressed blocks.
std::string compressed(const Array& a)
{
    const std::uint64_t bytes = std::uint64_t{a.size} * a.element;
    const std::uint64_t blocks = (bytes + kBlockBytes - 1) / kBlockBytes;
    std::vector<std::string> parts(static_cast<std::size_t>(blocks));
    const std::size_t per_block = kBlockBytes / a.element;
    // The blocks are independent: compressed by all cores, each thread taking the next block.
    std::atomic<std::size_t> next{0};
    std::exception_ptr failure;
    std::mutex failure_mutex;
    auto work = [&] {
        std::string raw(kBlockBytes, '\0');
        for (std::size_t b; (b = next.fetch_add(1)) < parts.size();) {
            try {
                const std::size_t first = b * per_block;
                const std::size_t count = std::min(per_block, a.size - first);
                a.fill(raw.data(), first, count);
                parts[b] = zlib_compress(raw.data(), count * a.element, kLevel);
            } catch (...) {
                const std::lock_guard<std::mutex> lock(failure_mutex);
                if (!failure) failure = std::current_exception();
                next = parts.size();
            }
        }
    };
    const auto threads = static_cast<std::size_t>(cmc33::detail::threads_for(0, static_cast<std::int64_t>(parts.size())));
    std::vector<std::thread> pool; // std::thread: the WebAssembly build's libc++ has no jthread
    for (std::size_t k = 1; k < threads; ++k) {
        try {
            pool.emplace_back(work);
        } catch (const std::system_error&) {
            break; // no more threads: the ones there (and this one) take every block
        }
    }
    work();
    for (std::thread& t : pool) t.join();
    if (failure) std::rethrow_exception(failure);
    std::string out((3 + blocks) * 8, '\0');
    store_le(out.data(), blocks);
    store_le(out.data() + 8, std::uint64_t{kBlockBytes});
    store_le(out.data() + 16, std::uint64_t{bytes % kBlockBytes});
    for (std::uint64_t b = 0; b < blocks; ++b) {
        store_le(out.data() + 24 + 8 * b, std::uint64_t{parts[static_cast<std::size_t>(b)].size()});
    }
    for (std::string& p : parts) {
        out += p;
        std::string().swap(p);
    }
    return out;
}

Array floats(std::string name, int components, const float* values, std::size_t size)
{
    return {"Float32", std::move(name), components, 4, size,
            [values](char* dst, std::size_t first, std::size_t n) { store_f32s_le(dst, values + first, n); }};
}

Array ints(std::string name, int components, const std::int32_t* values, std::size_t size)
{
    return {"Int32", std::move(name), components, 4, size, [values](char* dst, std::size_t first, std::size_t n) {
                for (std::size_t i = 0; i < n; ++i) store_le(dst + 4 * i, static_cast<std::uint32_t>(values[first + i]));
            }};
}

Array longs(std::string name, int components, const std::int64_t* values, std::size_t size)
{
    return {"Int64", std::move(name), components, 8, size, [values](char* dst, std::size_t first, std::size_t n) {
                for (std::size_t i = 0; i < n; ++i) store_le(dst + 8 * i, static_cast<std::uint64_t>(values[first + i]));
            }};
}

Array named(const MeshArray& a)
{
    return std::visit(
        [&](const auto& span) {
            using T = typename std::decay_t<decltype(span)>::element_type;
            if constexpr (std::is_same_v<T, const float>) {
                return floats(a.name, a.components, span.data(), span.size());
            } else if constexpr (std::is_same_v<T, const std::int32_t>) {
                return ints(a.name, a.components, span.data(), span.size());
            } else {
                return longs(a.name, a.components, span.data(), span.size());
            }
        },
        a.values);
}

} // namespace

void write_vtp(const Mesh& mesh, std::ostream& out, const MeshWriteOptions& options, const std::string& name)
{
    (void)name;
    const std::size_t n = mesh.vertex_count();
    const std::size_t m = mesh.triangle_count();
    const bool narrow = n <= static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max()) &&
                        3 * m <= static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max());
    const std::uint32_t* t = mesh.triangles.data();

    Array points;
    if (options.offset) {
        const Vec3 o = *options.offset;
        const float* p = mesh.positions.data();
        points = {"Float64", "Points", 3, 8, 3 * n, [o, p](char* dst, std::size_t first, std::size_t count) {
                      for (std::size_t i = 0; i < count; ++i) {
                          const std::size_t k = first + i;
                          store_le(dst + 8 * i, std::bit_cast<std::uint64_t>(o[k % 3] + static_cast<double>(p[k])));
                      }
                  }};
    } else {
        points = floats("Points", 3, mesh.positions.data(), 3 * n);
    }
    Array connectivity{narrow ? "Int32" : "Int64", "connectivity", 1, narrow ? 4u : 8u, 3 * m,
                       [t, narrow](char* dst, std::size_t first, std::size_t count) {
                           if (narrow) {
                               store_u32s_le(dst, t + first, count);
                           } else {
                               for (std::size_t i = 0; i < count; ++i) store_le(dst + 8 * i, std::uint64_t{t[first + i]});
                           }
                       }};
    Array offsets{narrow ? "Int32" : "Int64", "offsets", 1, narrow ? 4u : 8u, m,
                  [narrow](char* dst, std::size_t first, std::size_t count) {
                      for (std::size_t i = 0; i < count; ++i) {
                          const std::uint64_t end = 3 * std::uint64_t{first + i + 1};
                          if (narrow) {
                              store_le(dst + 4 * i, static_cast<std::uint32_t>(end));
                          } else {
                              store_le(dst + 8 * i, end);
                          }
                      }
                  }};
    std::vector<Array> point_data;
    if (mesh.has_normals()) point_data.push_back(floats("Normals", 3, mesh.normals.data(), 3 * n));
    for (const MeshArray& a : options.vertex_arrays) point_data.push_back(named(a));
    std::vector<Array> cell_data;
    for (const MeshArray& a : options.triangle_arrays) cell_data.push_back(named(a));

    // The appended section in the order of the XML below; each array's offset is known once the
    // arrays before it are compressed.
    std::vector<std::string> blobs;
    std::uint64_t at = 0;
    auto element = [&](const Array& a) {
        std::string e = "<DataArray type=\"" + a.type + "\"";
        if (!a.name.empty()) e += " Name=\"" + xml_escape(a.name) + "\"";
        if (a.components != 1) e += " NumberOfComponents=\"" + std::to_string(a.components) + "\"";
        e += " format=\"appended\" offset=\"" + std::to_string(at) + "\"/>\n";
        blobs.push_back(compressed(a));
        at += blobs.back().size();
        return e;
    };

    std::string xml = "<?xml version=\"1.0\"?>\n"
                      "<VTKFile type=\"PolyData\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\" "
                      "compressor=\"vtkZLibDataCompressor\">\n<PolyData>\n";
    xml += "<Piece NumberOfPoints=\"" + std::to_string(n) +
           "\" NumberOfVerts=\"0\" NumberOfLines=\"0\" NumberOfStrips=\"0\" NumberOfPolys=\"" + std::to_string(m) +
           "\">\n";
    xml += mesh.has_normals() ? "<PointData Normals=\"Normals\">\n" : "<PointData>\n";
    for (const Array& a : point_data) xml += element(a);
    xml += "</PointData>\n<CellData>\n";
    for (const Array& a : cell_data) xml += element(a);
    xml += "</CellData>\n<Points>\n" + element(points) + "</Points>\n";
    xml += "<Polys>\n" + element(connectivity);
    xml += element(offsets) + "</Polys>\n</Piece>\n</PolyData>\n<AppendedData encoding=\"raw\">\n_";

    OutputBuffer o(out);
    o.text(xml);
    for (std::string& b : blobs) {
        o.bytes(b.data(), b.size());
        std::string().swap(b);
    }
    o.text("\n</AppendedData>\n</VTKFile>\n");
    o.flush();
}

} // namespace cmc33::io::detail
