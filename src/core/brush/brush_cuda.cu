// Brush stage, CUDA backend.
#include "core/brush/brush_impl.h"
