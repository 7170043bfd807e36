// LaunchGraph's CUDA side: stream capture on the simulator's stream, instantiate, replay.
#include "core/exec/graph.h"

#include "core/exec/dispatch.h"
#if defined(WB_WITH_CUDA)
#include "core/exec/cuda_check.h"
#include "core/exec/stream.h"
#endif

namespace wb {

void LaunchGraph::reset() {
  drop();
  seen_ = 0;
}

#if defined(WB_WITH_CUDA)
void LaunchGraph::drop() {
  if (exec_) cudaGraphExecDestroy(static_cast<cudaGraphExec_t>(exec_));  // no throw from a destructor
  exec_ = nullptr;
  key_ = 0;
  launches_ = 0;
}

void LaunchGraph::begin() {
  drop();
  // Thread-local: another host thread's CUDA calls (the studio's UI) do not break the capture.
  WB_CUDA_CHECK(cudaStreamBeginCapture(cuda_stream(), cudaStreamCaptureModeThreadLocal));
}

void LaunchGraph::end(uint64_t key, int64_t launches) {
  cudaGraph_t graph = nullptr;
  WB_CUDA_CHECK(cudaStreamEndCapture(cuda_stream(), &graph));
  cudaGraphExec_t exec = nullptr;
  const cudaError_t err = cudaGraphInstantiate(&exec, graph, 0);
  cudaGraphDestroy(graph);
  WB_CUDA_CHECK(err);
  exec_ = exec;
  key_ = key;
  launches_ = launches;
}

void LaunchGraph::abandon() {
  cudaGraph_t graph = nullptr;
  if (cudaStreamEndCapture(cuda_stream(), &graph) == cudaSuccess && graph) cudaGraphDestroy(graph);
  (void)cudaGetLastError();  // the launch's own error is the one reported
  reset();
}

void LaunchGraph::replay(bool count) {
  WB_CUDA_CHECK(cudaGraphLaunch(static_cast<cudaGraphExec_t>(exec_), cuda_stream()));
  if (count)
    for (int64_t i = 0; i < launches_; ++i) mem::count_launch();
}
#else
void LaunchGraph::drop() {
  exec_ = nullptr;
  key_ = 0;
  launches_ = 0;
}
void LaunchGraph::begin() { detail::throw_no_cuda(); }
void LaunchGraph::end(uint64_t, int64_t) {}
void LaunchGraph::abandon() {}
void LaunchGraph::replay(bool) {}
#endif

}  // namespace wb
