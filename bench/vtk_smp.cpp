// Compiled as C++17; see vtk_smp.hpp.
#include "vtk_smp.hpp"

#include <vtkSMPTools.h>

namespace cmc33::bench {

void vtk_smp_initialize(int threads) { vtkSMPTools::Initialize(threads); }
int vtk_smp_threads() { return vtkSMPTools::GetEstimatedNumberOfThreads(); }
const char* vtk_smp_backend() { return vtkSMPTools::GetBackend(); }

} // namespace cmc33::bench
