#pragma once
// vtkSMPTools, behind functions: VTK 9.1's vtkSMPTools.h does not compile as C++20 (it names a
// constructor with a template-id, which C++20 forbids), so vtk_smp.cpp includes it as C++17 and
// cmc33_vtk_bench, a C++20 program like the rest of cmc33, calls these.

namespace cmc33::bench {

/// vtkSMPTools::Initialize(threads): the number of threads SMP loops use, 0 = all cores.
void vtk_smp_initialize(int threads);
/// vtkSMPTools::GetEstimatedNumberOfThreads().
int vtk_smp_threads();
/// vtkSMPTools::GetBackend(): "Sequential", "STDThread", "TBB" or "OpenMP".
const char* vtk_smp_backend();

} // namespace cmc33::bench
