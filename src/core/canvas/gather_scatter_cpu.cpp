// CPU backend of the gather/scatter stage.
#include "core/canvas/gather_scatter_impl.h"
