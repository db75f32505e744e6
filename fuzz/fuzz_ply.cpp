// libFuzzer target: PLY meshes (ascii, binary_little_endian, binary_big_endian) from memory.

#include <cstddef>
#include <cstdint>
#include <string_view>

#include "fuzz_common.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    const std::string_view bytes(reinterpret_cast<const char*>(data), size);
    return cmc33::fuzz::run("fuzz.ply", [&] {
        return cmc33::io::read_mesh_from_memory(bytes, cmc33::io::MeshFormat::ply, "fuzz.ply");
    });
}
