// Brush stage, CPU (OpenMP) backend.
#include "core/brush/brush_impl.h"
