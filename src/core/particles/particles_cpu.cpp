#include "core/particles/particles_impl.h"
