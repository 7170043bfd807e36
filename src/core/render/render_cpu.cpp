#include "core/render/render_impl.h"
