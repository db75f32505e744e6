// cmc33_vtk_bench: times VTK's isosurface filters on a volume file, for bench/run_bench.sh.
//
//   cmc33_vtk_bench FILE ISO [--repeat 5] [--algorithm flying-edges|marching-cubes] [--threads N]
//
// The volume is read with cmc33::io::read_volume, so every tool reads exactly the same samples,
// and handed to a vtkImageData as an array of the SAME scalar type (uint8 stays vtkUnsignedCharArray,
// nothing is converted to float). The array shares the Volume's buffer (SetVoidArray with save = 1)
// instead of copying it: the samples and their type are the same, and the process holds the input
// once, as the cmc33 CLI does, so peak-memory figures compare. None of that is timed.
// Each run builds a new filter (ComputeNormals, ComputeGradients and ComputeScalars off) outside
// the timing, and only Update() is timed. One JSON line is printed:
//   {"tool": "vtk-flying-edges", "seconds": median, "runs_seconds": [...], "points": n,
//    "triangles": n, "threads": n, "smp_backend": "TBB", "vtk_version": "9.1.0", ...}
//
// vtkSMPTools is called through vtk_smp.hpp (VTK 9.1's header is not valid C++20).
//
// Exit codes: 0 measured, 1 the file could not be read or the filter failed, 2 usage error.

#include <vtkDataArray.h>
#include <vtkFlyingEdges3D.h>
#include <vtkImageData.h>
#include <vtkMarchingCubes.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPolyData.h>
#include <vtkSmartPointer.h>
#include <vtkType.h>
#include <vtkVersion.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <iostream>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include "cmc33/error.hpp"
#include "cmc33/io.hpp"
#include "cmc33/volume.hpp"
#include "vtk_smp.hpp"

namespace {

constexpr const char* kUsage =
    "usage: cmc33_vtk_bench FILE ISO [--repeat N=5] [--algorithm flying-edges|marching-cubes] [--threads N=1]\n"
    "Extracts the isosurface ISO of FILE (any volume cmc33 reads) N times with vtkFlyingEdges3D\n"
    "(default) or vtkMarchingCubes, normals, gradients and scalars off, times Update() alone, and\n"
    "prints one JSON line with the median time. --threads sets vtkSMPTools::Initialize(N) (0: all\n"
    "cores) for flying-edges; vtkMarchingCubes is serial and takes only --threads 1.\n";

struct UsageError {
    std::string message;
};

enum class Algorithm { flying_edges, marching_cubes };

struct Args {
    std::string file;
    double iso = 0;
    int repeat = 5;
    Algorithm algorithm = Algorithm::flying_edges;
    int threads = 1;
};

int parse_int(std::string_view text, std::string_view what, int min, int max)
{
    int value = 0;
    const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
    if (ec != std::errc{} || end != text.data() + text.size() || value < min || value > max) {
        throw UsageError{std::string(what) + " \"" + std::string(text) + "\" is not an integer in [" +
                         std::to_string(min) + ", " + std::to_string(max) + "]"};
    }
    return value;
}

double parse_iso(const std::string& text)
{
    char* end = nullptr;
    const double value = std::strtod(text.c_str(), &end);
    if (text.empty() || end != text.c_str() + text.size() || !std::isfinite(value)) {
        throw UsageError{"ISO \"" + text + "\" is not a finite number"};
    }
    return value;
}

Args parse_args(const std::vector<std::string>& argv)
{
    Args args;
    std::vector<std::string> positional;
    for (std::size_t i = 0; i < argv.size(); ++i) {
        const std::string& a = argv[i];
        const bool has_value = i + 1 < argv.size();
        if (a == "--repeat" || a == "--algorithm" || a == "--threads") {
            if (!has_value) throw UsageError{a + " needs a value"};
            const std::string& v = argv[++i];
            if (a == "--repeat") {
                args.repeat = parse_int(v, "--repeat", 1, 1000000);
            } else if (a == "--threads") {
                args.threads = parse_int(v, "--threads", 0, 4096);
            } else if (v == "flying-edges") {
                args.algorithm = Algorithm::flying_edges;
            } else if (v == "marching-cubes") {
                args.algorithm = Algorithm::marching_cubes;
            } else {
                throw UsageError{"--algorithm \"" + v + "\" is unknown; expected flying-edges or marching-cubes"};
            }
        } else if (a.size() > 1 && a[0] == '-' && !(std::isdigit(static_cast<unsigned char>(a[1])) || a[1] == '.')) {
            throw UsageError{"unknown option \"" + a + "\""};
        } else {
            positional.push_back(a);
        }
    }
    if (positional.size() != 2) {
        throw UsageError{"expected FILE and ISO, got " + std::to_string(positional.size()) + " positional arguments"};
    }
    args.file = positional[0];
    args.iso = parse_iso(positional[1]);
    if (args.algorithm == Algorithm::marching_cubes && args.threads != 1) {
        throw UsageError{"vtkMarchingCubes is serial: --threads must be 1 with --algorithm marching-cubes"};
    }
    return args;
}

int vtk_type_of(cmc33::ScalarType type)
{
    switch (type) {
    case cmc33::ScalarType::i8: return VTK_SIGNED_CHAR;
    case cmc33::ScalarType::u8: return VTK_UNSIGNED_CHAR;
    case cmc33::ScalarType::i16: return VTK_SHORT;
    case cmc33::ScalarType::u16: return VTK_UNSIGNED_SHORT;
    case cmc33::ScalarType::i32: return VTK_INT;
    case cmc33::ScalarType::u32: return VTK_UNSIGNED_INT;
    case cmc33::ScalarType::f32: return VTK_FLOAT;
    case cmc33::ScalarType::f64: break;
    }
    return VTK_DOUBLE;
}

std::string json_string(std::string_view s)
{
    std::string out = "\"";
    for (const char c : s) {
        if (c == '"' || c == '\\') {
            out += '\\';
            out += c;
        } else if (static_cast<unsigned char>(c) < 0x20) {
            char buf[8];
            std::snprintf(buf, sizeof buf, "\\u%04x", static_cast<unsigned>(static_cast<unsigned char>(c)));
            out += buf;
        } else {
            out += c;
        }
    }
    return out + "\"";
}

std::string json_number(double v)
{
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.9g", v);
    return buf;
}

double median(std::vector<double> values)
{
    std::sort(values.begin(), values.end());
    const std::size_t n = values.size();
    return n % 2 == 1 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

struct Run {
    double seconds = 0;
    vtkIdType points = 0;
    vtkIdType triangles = 0;
};

template <class Filter> Run run_filter(vtkImageData* image, double iso)
{
    vtkNew<Filter> filter;
    filter->SetInputData(image);
    filter->SetValue(0, iso);
    filter->SetComputeNormals(false);
    filter->SetComputeGradients(false);
    filter->SetComputeScalars(false);
    const auto start = std::chrono::steady_clock::now();
    filter->Update();
    const auto stop = std::chrono::steady_clock::now();
    vtkPolyData* mesh = filter->GetOutput();
    return Run{std::chrono::duration<double>(stop - start).count(), mesh->GetNumberOfPoints(),
               mesh->GetNumberOfPolys()};
}

int run(const Args& args)
{
    cmc33::Volume volume = cmc33::io::read_volume(args.file);
    const cmc33::Index3& d = volume.dims();

    vtkSmartPointer<vtkDataArray> samples = vtkSmartPointer<vtkDataArray>::Take(
        vtkDataArray::CreateDataArray(vtk_type_of(volume.type())));
    samples->SetNumberOfComponents(1);
    samples->SetVoidArray(volume.bytes(), static_cast<vtkIdType>(volume.sample_count()), 1);
    samples->SetName("samples");
    vtkNew<vtkImageData> image;
    image->SetDimensions(static_cast<int>(d[0]), static_cast<int>(d[1]), static_cast<int>(d[2]));
    image->SetSpacing(volume.spacing().data());
    image->SetOrigin(volume.origin().data());
    image->GetPointData()->SetScalars(samples);

    if (args.algorithm == Algorithm::flying_edges) cmc33::bench::vtk_smp_initialize(args.threads);
    const int threads = args.algorithm == Algorithm::flying_edges ? cmc33::bench::vtk_smp_threads() : 1;

    std::vector<double> runs;
    Run last;
    for (int r = 0; r < args.repeat; ++r) {
        last = args.algorithm == Algorithm::flying_edges ? run_filter<vtkFlyingEdges3D>(image, args.iso)
                                                         : run_filter<vtkMarchingCubes>(image, args.iso);
        runs.push_back(last.seconds);
    }

    std::string runs_json = "[";
    for (std::size_t i = 0; i < runs.size(); ++i) runs_json += (i ? ", " : "") + json_number(runs[i]);
    runs_json += "]";
    const char* tool = args.algorithm == Algorithm::flying_edges ? "vtk-flying-edges" : "vtk-marching-cubes";
    std::cout << "{\"tool\": " << json_string(tool) << ", \"file\": " << json_string(args.file)
              << ", \"iso\": " << json_number(args.iso) << ", \"dims\": [" << d[0] << ", " << d[1] << ", " << d[2]
              << "], \"type\": " << json_string(cmc33::type_name(volume.type()))
              << ", \"seconds\": " << json_number(median(runs)) << ", \"runs_seconds\": " << runs_json
              << ", \"points\": " << last.points << ", \"triangles\": " << last.triangles
              << ", \"threads\": " << threads << ", \"smp_backend\": " << json_string(cmc33::bench::vtk_smp_backend())
              << ", \"vtk_version\": " << json_string(vtkVersion::GetVTKVersion()) << "}\n";
    return 0;
}

} // namespace

int main(int argc, char** argv)
{
    try {
        const std::vector<std::string> argv_list(argv + 1, argv + argc);
        if (argv_list.size() == 1 && (argv_list[0] == "-h" || argv_list[0] == "--help")) {
            std::cout << kUsage;
            return 0;
        }
        return run(parse_args(argv_list));
    } catch (const UsageError& e) {
        std::cerr << "cmc33_vtk_bench: " << e.message << " (try --help)\n";
        return 2;
    } catch (const std::exception& e) {
        std::cerr << "cmc33_vtk_bench: " << e.what() << '\n';
        return 1;
    }
}
