// Grid stage drivers, CPU backend (OpenMP).
#include "core/grid/grid_impl.h"
