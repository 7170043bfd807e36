#include "core/particles/sample_grid_impl.h"
