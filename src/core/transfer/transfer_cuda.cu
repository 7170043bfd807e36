// Transfer stage, CUDA backend: the drivers of transfer_impl.h compiled by nvcc.
#include "core/transfer/transfer_impl.h"
