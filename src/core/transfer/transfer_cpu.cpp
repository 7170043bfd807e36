// Transfer stage, CPU backend (OpenMP): the drivers of transfer_impl.h compiled by the host compiler.
#include "core/transfer/transfer_impl.h"
