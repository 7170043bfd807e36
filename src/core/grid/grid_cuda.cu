// Grid stage drivers, CUDA backend.
#include "core/grid/grid_impl.h"
