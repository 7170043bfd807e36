// LaunchGraph's and LaunchLoop's CUDA side: stream capture on the simulator's stream (into a
// conditional while node's body for a loop), instantiate, replay.
#include "core/exec/graph.h"

#include "core/exec/dispatch.h"
#if defined(WB_WITH_CUDA)
#include "core/exec/cuda_check.h"
#include "core/exec/stream.h"
#endif

namespace wb {
#if defined(WB_WITH_CUDA)
namespace detail {
void launch_loop_condition(unsigned long long handle, const uint32_t* go);  // graph_cuda.cu
}
#endif

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

void LaunchLoop::drop() {
  if (exec_) cudaGraphExecDestroy(static_cast<cudaGraphExec_t>(exec_));  // no throw from a destructor
  if (graph_) cudaGraphDestroy(static_cast<cudaGraph_t>(graph_));
  exec_ = nullptr;
  graph_ = nullptr;
  key_ = 0;
  launches_ = 0;
}

void LaunchLoop::begin() {
  drop();
  cudaGraph_t graph = nullptr;
  WB_CUDA_CHECK(cudaGraphCreate(&graph, 0));
  graph_ = graph;
  // A do-while: the handle is 1 at each launch of the graph (the body runs once at least), and
  // the body's last kernel sets it from the flag.
  cudaGraphConditionalHandle handle{};
  WB_CUDA_CHECK(cudaGraphConditionalHandleCreate(&handle, graph, 1, cudaGraphCondAssignDefault));
  handle_ = uint64_t(handle);
  cudaGraphNodeParams p{};
  p.type = cudaGraphNodeTypeConditional;
  p.conditional.handle = handle;
  p.conditional.type = cudaGraphCondTypeWhile;
  p.conditional.size = 1;
  cudaGraphNode_t node = nullptr;
  WB_CUDA_CHECK(cudaGraphAddNode(&node, graph, nullptr, nullptr, 0, &p));
  WB_CUDA_CHECK(cudaStreamBeginCaptureToGraph(cuda_stream(), p.conditional.phGraph_out[0], nullptr, nullptr, 0,
                                              cudaStreamCaptureModeThreadLocal));
}

void LaunchLoop::end(uint64_t key, const uint32_t* go, int64_t launches) {
  detail::launch_loop_condition(handle_, go);
  cudaGraph_t body = nullptr;
  WB_CUDA_CHECK(cudaStreamEndCapture(cuda_stream(), &body));  // the node's own body graph
  cudaGraphExec_t exec = nullptr;
  WB_CUDA_CHECK(cudaGraphInstantiate(&exec, static_cast<cudaGraph_t>(graph_), 0));
  exec_ = exec;
  key_ = key;
  launches_ = launches;
}

void LaunchLoop::abandon() {
  cudaGraph_t graph = nullptr;
  (void)cudaStreamEndCapture(cuda_stream(), &graph);  // the body belongs to graph_
  (void)cudaGetLastError();  // the launch's own error is the one reported
  drop();
}

void LaunchLoop::replay() {
  WB_CUDA_CHECK(cudaGraphLaunch(static_cast<cudaGraphExec_t>(exec_), cuda_stream()));
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
void LaunchLoop::drop() {
  exec_ = nullptr;
  graph_ = nullptr;
  key_ = 0;
  launches_ = 0;
}
void LaunchLoop::begin() { detail::throw_no_cuda(); }
void LaunchLoop::end(uint64_t, const uint32_t*, int64_t) {}
void LaunchLoop::abandon() {}
void LaunchLoop::replay() {}
#endif

}  // namespace wb
