#include "core/exec/selftest_impl.h"
