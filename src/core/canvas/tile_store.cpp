#include "core/canvas/tile_store.h"

#include <algorithm>
#include <cmath>

#include "core/exec/algorithms.h"

namespace wb {

WB_DEFINE_DISPATCHERS(WB_TILE_STORE_KERNELS)

TileStore::TileStore(const Device& device, CanvasDims dims) : device_(device), dims_(dims) {
  WB_REQUIRE(dims.width > 0 && dims.height > 0 && dims.depth > 0, "canvas dimensions must be positive");
  WB_REQUIRE(dims.width <= 65536 && dims.height <= 65536 && dims.depth <= 1024,
             "canvas dimensions too large (at most 65536 x 65536 x 1024 cells)");
  tiles_x_ = (dims.width + kTileSize - 1) / kTileSize;
  tiles_y_ = (dims.height + kTileSize - 1) / kTileSize;
  host_slot_.assign(size_t(tiles_x_) * tiles_y_, -1);
  slot_of_tile_.set_device(device);
  slot_of_tile_.copy_from_host(host_slot_);
  for (auto* b : {&pigment_r_, &pigment_y_, &pigment_b_, &oil_, &dryness_}) b->set_device(device);
  density_.set_device(device);
  tile_flags_.set_device(device);
  dried_to_.set_device(device);
  tile_of_slot_dev_.set_device(device);
  slots_used_dev_ = DeviceBuffer<int32_t>(device, 1);
  slots_used_dev_.fill_zero();
  ws_ = Workspace(device);
  mass_before_.set_device(device);
  mass_after_.set_device(device);
  mass_sums_ = DeviceBuffer<double>(device, 2);
  mass_sums_.fill_zero();
}

double TileStore::total_density() const {
  if (mass_pending_) {
    double sums[2];
    mass_sums_.copy_to_host(sums, 2);
    fold_mass_sums(sums);
  }
  return mass_;
}

void TileStore::take_mass_sums(const double sums[2]) { fold_mass_sums(sums); }

void TileStore::fold_mass_sums(const double sums[2]) const {
  mass_ += sums[0] - sums[1];
  mass_sums_.fill_zero();
  mass_pending_ = false;
}

TileStoreView TileStore::view() {
  TileStoreView v{};
  v.slot_of_tile = slot_of_tile_.data();
  v.density = density_.data();
  v.pigment_r = pigment_r_.data();
  v.pigment_y = pigment_y_.data();
  v.pigment_b = pigment_b_.data();
  v.oil = oil_.data();
  v.dryness = dryness_.data();
  v.dried_to = dried_to_.data();
  v.clock = float(clock_);
  v.width = dims_.width;
  v.height = dims_.height;
  v.depth = dims_.depth;
  v.tiles_x = tiles_x_;
  v.tiles_y = tiles_y_;
  return v;
}

void TileStore::grow_pool(int32_t slots) {
  if (slots <= slot_capacity_) return;
  int32_t cap = std::max<int32_t>(slot_capacity_, 8);
  while (cap < slots) cap += cap / 2;
  const size_t cells = size_t(cap) * size_t(tile_cells());
  const size_t used = size_t(slot_capacity_) * size_t(tile_cells());
  density_.grow_keep(cells);
  for (auto* b : {&pigment_r_, &pigment_y_, &pigment_b_, &oil_, &dryness_}) b->grow_keep(cells);
  dried_to_.grow_keep(size_t(cap));
  tile_of_slot_dev_.grow_keep(size_t(cap));
  // New slots start empty.
  mem::fill_zero(device_, density_.data() + used, (cells - used) * sizeof(float));
  for (auto* b : {&pigment_r_, &pigment_y_, &pigment_b_, &oil_, &dryness_})
    mem::fill_zero(device_, b->data() + used, (cells - used) * sizeof(uint16_t));
  slot_capacity_ = cap;
}

int TileStore::allocated_tiles() const {
  sync_host();
  return slots_used_;
}

void TileStore::take_tiles_used(int32_t used) { bound_ = known_used_ = used; }

void TileStore::sync_host() const {
  if (!host_stale_) return;
  // The device's scatters allocated tiles and brought the window's tiles up to the clock.
  int32_t used = 0;
  slots_used_dev_.copy_to_host(&used, 1);
  tile_of_slot_.resize(size_t(used));
  host_dried_to_.resize(size_t(used));
  if (used > slots_used_) {
    const size_t from = size_t(slots_used_), n = size_t(used - slots_used_);
    tile_of_slot_dev_.copy_range_to_host(tile_of_slot_.data() + from, from, n);
    for (size_t s = from; s < size_t(used); ++s) host_slot_[size_t(tile_of_slot_[s])] = int32_t(s);
  }
  if (used > 0) dried_to_.copy_range_to_host(host_dried_to_.data(), 0, size_t(used));
  slots_used_ = used;
  bound_ = known_used_ = used;
  host_stale_ = false;
}

int32_t TileStore::ensure_slot(int tile_id) {
  sync_host();
  int32_t& s = host_slot_[size_t(tile_id)];
  if (s >= 0) return s;
  grow_pool(slots_used_ + 1);
  s = slots_used_++;
  bound_ = std::max<int64_t>(bound_, slots_used_);
  known_used_ = slots_used_;
  tile_of_slot_.push_back(tile_id);
  slot_of_tile_.copy_range_from_host(&s, size_t(tile_id), 1);
  tile_of_slot_dev_.copy_range_from_host(&tile_id, size_t(s), 1);
  slots_used_dev_.copy_from_host(&slots_used_, 1);
  // A new tile is empty: it is up to date with the clock.
  host_dried_to_.resize(size_t(slots_used_));
  host_dried_to_[size_t(s)] = float(clock_);
  dried_to_.copy_range_from_host(&host_dried_to_[size_t(s)], size_t(s), 1);
  return s;
}

void TileStore::gather(PaintWindow& window) {
  WB_REQUIRE(window.device() == device_, "gather: window and canvas live on different devices");
  tiles_gather_window(device_, view(), window.view());
}

void TileStore::scatter(PaintWindow& window) {
  WB_REQUIRE(window.device() == device_, "scatter: window and canvas live on different devices");
  const Int3 o = window.origin(), n = window.dims();
  const int x0 = std::max(o.x, 0), y0 = std::max(o.y, 0);
  const int x1 = std::min(o.x + n.x, dims_.width) - 1, y1 = std::min(o.y + n.y, dims_.height) - 1;
  if (x1 < x0 || y1 < y0 || o.z >= dims_.depth || o.z + n.z <= 0) return;  // window entirely off-canvas
  const int tx0 = x0 / kTileSize, ty0 = y0 / kTileSize, ntx = x1 / kTileSize - tx0 + 1;
  // The tiles that receive paint are allocated on the device, from a pool sized for every tile
  // of the window the host does not know to be allocated: no read (docs/ARCHITECTURE.md "The
  // sparse canvas"). The record of the step tells the host how many were taken (take_tiles_used).
  const int nty = y1 / kTileSize - ty0 + 1;
  // Scatters with no record between them (a grid stepped on its own, flushes) would raise the
  // bound by a window's tiles each: past two windows' worth the host reads the table first.
  if (bound_ > known_used_ + 2 * int64_t(ntx) * nty) sync_host();
  int64_t unknown = 0;
  for (int j = 0; j < nty; ++j)
    for (int i = 0; i < ntx; ++i) unknown += host_slot_[size_t((ty0 + j) * tiles_x_ + tx0 + i)] < 0;
  bound_ += unknown;
  grow_pool(int32_t(bound_));
  tile_flags_.resize(size_t(ntx) * nty);
  tile_flags_.fill_zero();
  tiles_allocate_painted(device_, view(), window.view(), tx0, ty0, ntx, nty, tile_flags_.data(),
                         TileSlots{slot_of_tile_.data(), tile_of_slot_dev_.data(), slots_used_dev_.data()});
  host_stale_ = true;
  // The window covers these tiles only in part: the rest of each must carry its drying before
  // the tile is marked up to date.
  tiles_settle_window(device_, view(), tx0, ty0, ntx, nty);
  // The running total: what the scatter writes less what it overwrites.
  const int64_t cells = window.view().size();
  mass_before_.resize(size_t(cells));
  mass_after_.resize(size_t(cells));
  tiles_scatter_window(device_, view(), window.view(), mass_before_.data(), mass_after_.data());
  reduce_sum_add_into(device_, mass_after_.data(), cells, mass_sums_.data(), ws_);
  reduce_sum_add_into(device_, mass_before_.data(), cells, mass_sums_.data() + 1, ws_);
  mass_pending_ = true;
}

void TileStore::advance_drying(double amount) {
  WB_REQUIRE(std::isfinite(amount) && amount >= 0.0, "advance_drying: amount must be finite and non-negative");
  clock_ += amount;
}

void TileStore::dry_all() {
  sync_host();
  if (slots_used_ == 0) return;
  tiles_dry_all(device_, view(), int64_t(slots_used_) * tile_cells());
}

void TileStore::lay_weave(const WeaveField& w) {
  sync_host();
  WB_REQUIRE(slots_used_ == 0, "TileStore::lay_weave: the canvas is not empty");
  // Slot = tile id, allocated at once (one index upload, not one per tile).
  const int32_t n = tiles_x_ * tiles_y_;
  grow_pool(n);
  tile_of_slot_.resize(size_t(n));
  for (int32_t s = 0; s < n; ++s) host_slot_[size_t(s)] = tile_of_slot_[size_t(s)] = s;
  slots_used_ = n;
  bound_ = known_used_ = n;
  host_dried_to_.assign(size_t(n), float(clock_));
  slot_of_tile_.copy_from_host(host_slot_);
  tile_of_slot_dev_.copy_range_from_host(tile_of_slot_.data(), 0, size_t(n));
  slots_used_dev_.copy_from_host(&slots_used_, 1);
  dried_to_.copy_range_from_host(host_dried_to_.data(), 0, size_t(n));
  tiles_lay_weave(device_, view(), w, int64_t(n) * kTileSize * kTileSize);
  mass_ = recount_density(ws_);
}

void TileStore::clear() {
  std::fill(host_slot_.begin(), host_slot_.end(), -1);  // the mirror may miss the device's newest
  tile_of_slot_.clear();
  host_dried_to_.clear();
  slots_used_ = 0;
  bound_ = known_used_ = 0;
  host_stale_ = false;
  slots_used_dev_.fill_zero();
  mass_ = 0.0;
  mass_sums_.fill_zero();
  mass_pending_ = false;
  slot_of_tile_.copy_from_host(host_slot_);
  if (slot_capacity_ > 0) {
    density_.fill_zero();
    for (auto* b : {&pigment_r_, &pigment_y_, &pigment_b_, &oil_, &dryness_}) b->fill_zero();
  }
}

void TileStore::copy_from(const TileStore& src) {
  WB_REQUIRE(src.dims_ == dims_, "TileStore::copy_from: the canvases differ in size");
  if (&src == this) return;
  if (!(src.device_ == device_)) {
    clear();
    for (int id : src.allocated_tile_ids()) write_tile(src.read_tile(id));
    return;
  }
  // The device's slot table is the truth: copied on the device with the slots it may use
  // (bound_), and the host's mirror as stale as src's.
  clear();
  grow_pool(int32_t(src.bound_));
  host_slot_ = src.host_slot_;
  tile_of_slot_ = src.tile_of_slot_;
  host_dried_to_ = src.host_dried_to_;
  slots_used_ = src.slots_used_;
  bound_ = src.bound_;
  known_used_ = src.known_used_;
  host_stale_ = src.host_stale_;
  clock_ = src.clock_;
  mass_ = src.mass_;  // and the sums src has not read yet, on the device below
  mem::copy_on_device(device_, mass_sums_.data(), src.mass_sums_.data(), 2 * sizeof(double));
  mass_pending_ = src.mass_pending_;
  mem::copy_on_device(device_, slot_of_tile_.data(), src.slot_of_tile_.data(), host_slot_.size() * sizeof(int32_t));
  mem::copy_on_device(device_, slots_used_dev_.data(), src.slots_used_dev_.data(), sizeof(int32_t));
  const size_t slots = size_t(bound_), cells = slots * size_t(tile_cells());
  if (cells == 0) return;
  mem::copy_on_device(device_, density_.data(), src.density_.data(), cells * sizeof(float));
  const DeviceBuffer<uint16_t>* from[] = {&src.pigment_r_, &src.pigment_y_, &src.pigment_b_, &src.oil_, &src.dryness_};
  DeviceBuffer<uint16_t>* to[] = {&pigment_r_, &pigment_y_, &pigment_b_, &oil_, &dryness_};
  for (int f = 0; f < 5; ++f) mem::copy_on_device(device_, to[f]->data(), from[f]->data(), cells * sizeof(uint16_t));
  mem::copy_on_device(device_, dried_to_.data(), src.dried_to_.data(), slots * sizeof(float));
  mem::copy_on_device(device_, tile_of_slot_dev_.data(), src.tile_of_slot_dev_.data(), slots * sizeof(int32_t));
}

size_t TileStore::memory_bytes() const {
  size_t b = host_slot_.size() * sizeof(int32_t) * 2 + tile_of_slot_.capacity() * sizeof(int32_t);
  b += density_.bytes() + pigment_r_.bytes() + pigment_y_.bytes() + pigment_b_.bytes() + oil_.bytes() +
       dryness_.bytes();
  return b;
}

double TileStore::recount_density(Workspace& ws) const {
  sync_host();
  if (slots_used_ == 0) return 0.0;
  return reduce_sum(device_, density_.data(), int64_t(slots_used_) * tile_cells(), ws);
}

PaintCell TileStore::read_cell(int x, int y, int z) const {
  PaintCell c;
  if (x < 0 || y < 0 || z < 0 || x >= dims_.width || y >= dims_.height || z >= dims_.depth) return c;
  sync_host();
  const int32_t slot = host_slot_[size_t(y / kTileSize) * tiles_x_ + x / kTileSize];
  if (slot < 0) return c;
  const size_t at = size_t(slot) * tile_cells() + size_t((z * kTileSize + y % kTileSize) * kTileSize + x % kTileSize);
  density_.copy_range_to_host(&c.density, at, 1);
  uint16_t q[5];
  pigment_r_.copy_range_to_host(&q[0], at, 1);
  pigment_y_.copy_range_to_host(&q[1], at, 1);
  pigment_b_.copy_range_to_host(&q[2], at, 1);
  oil_.copy_range_to_host(&q[3], at, 1);
  dryness_.copy_range_to_host(&q[4], at, 1);
  c.pigment_r = decode_unorm16(q[0]);
  c.pigment_y = decode_unorm16(q[1]);
  c.pigment_b = decode_unorm16(q[2]);
  c.oil = decode_unorm16(q[3]);
  c.dryness = decode_unorm16(q[4]);
  if (c.density > 0.f) c.dryness = with_drying(c.dryness, owed_drying(slot));
  return c;
}

std::vector<int> TileStore::allocated_tile_ids() const {
  sync_host();
  return {tile_of_slot_.begin(), tile_of_slot_.end()};
}

bool TileStore::tile_allocated(int tile_id) const {
  WB_REQUIRE(tile_id >= 0 && size_t(tile_id) < host_slot_.size(), "tile_allocated: tile id out of range");
  sync_host();
  return host_slot_[size_t(tile_id)] >= 0;
}

TileData TileStore::read_tile(int tile_id) const {
  TileData d;
  read_tile(tile_id, d);
  return d;
}

void TileStore::read_tile(int tile_id, TileData& d) const {
  WB_REQUIRE(tile_id >= 0 && size_t(tile_id) < host_slot_.size(), "read_tile: tile id out of range");
  sync_host();
  d.tile_x = tile_id % tiles_x_;
  d.tile_y = tile_id / tiles_x_;
  const size_t n = size_t(tile_cells());
  const int32_t slot = host_slot_[size_t(tile_id)];
  if (slot < 0) {
    d.density.assign(n, 0.f);
    for (auto* v : {&d.pigment_r, &d.pigment_y, &d.pigment_b, &d.oil, &d.dryness}) v->assign(n, 0);
    return;
  }
  // Every element is copied over: a vector of the right size keeps its memory as it is.
  d.density.resize(n);
  for (auto* v : {&d.pigment_r, &d.pigment_y, &d.pigment_b, &d.oil, &d.dryness}) v->resize(n);
  const size_t at = size_t(slot) * n;
  density_.copy_range_to_host(d.density.data(), at, n);
  pigment_r_.copy_range_to_host(d.pigment_r.data(), at, n);
  pigment_y_.copy_range_to_host(d.pigment_y.data(), at, n);
  pigment_b_.copy_range_to_host(d.pigment_b.data(), at, n);
  oil_.copy_range_to_host(d.oil.data(), at, n);
  dryness_.copy_range_to_host(d.dryness.data(), at, n);
  const float lag = owed_drying(slot);
  if (lag > 0.f)
    for (size_t i = 0; i < n; ++i)
      if (d.density[i] > 0.f) d.dryness[i] = encode_unorm16(with_drying(decode_unorm16(d.dryness[i]), lag));
}

void TileStore::write_tile(const TileData& d) {
  WB_REQUIRE(d.tile_x >= 0 && d.tile_y >= 0 && d.tile_x < tiles_x_ && d.tile_y < tiles_y_,
             "write_tile: tile position outside the canvas");
  const size_t n = size_t(tile_cells());
  WB_REQUIRE(d.density.size() == n && d.pigment_r.size() == n && d.pigment_y.size() == n &&
                 d.pigment_b.size() == n && d.oil.size() == n && d.dryness.size() == n,
             "write_tile: field sizes do not match the canvas depth");
  const int32_t slot = ensure_slot(d.tile_y * tiles_x_ + d.tile_x);
  const size_t at = size_t(slot) * n;
  std::vector<float> old(n);
  density_.copy_range_to_host(old.data(), at, n);
  for (size_t i = 0; i < n; ++i) mass_ += double(d.density[i]) - double(old[i]);
  density_.copy_range_from_host(d.density.data(), at, n);
  pigment_r_.copy_range_from_host(d.pigment_r.data(), at, n);
  pigment_y_.copy_range_from_host(d.pigment_y.data(), at, n);
  pigment_b_.copy_range_from_host(d.pigment_b.data(), at, n);
  oil_.copy_range_from_host(d.oil.data(), at, n);
  dryness_.copy_range_from_host(d.dryness.data(), at, n);
  host_dried_to_[size_t(slot)] = float(clock_);
  dried_to_.copy_range_from_host(&host_dried_to_[size_t(slot)], size_t(slot), 1);
}

}  // namespace wb
