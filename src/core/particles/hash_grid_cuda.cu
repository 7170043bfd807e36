#include "core/particles/hash_grid_impl.h"
