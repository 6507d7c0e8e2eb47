// Parallel propagation of one run (GeodesicOptions::threads > 1, vertex-sorted variants).
//
// The sequential engine takes one vertex at a time and crosses the lists it sets moving one at a time, so
// every step sees the last one's result. Here the wavefront advances by a band instead: every queued vertex
// within band_width_ of the nearest joins the traversed area, and the lists set moving then cross in rounds.
// A round crosses all lists scheduled when it starts, each on whichever thread takes it, pruning it first
// (Rules 2 and 3) and reading only its own list and the distances as they stood at the round's start, and
// frees it; then, in the round's order, what they found at their opposite corners is applied; then each
// edge reached by crossed windows joins them to its list, every edge on one thread, the windows in the
// round's order. Nothing a thread computes depends on what another thread does or when, so the distances
// are the same, bit for bit, for any number of threads: only the band (a property of the mesh) shapes the
// work.
//
// Exactness does not depend on the order of propagation (every window is propagated until pruned, and the
// pruning compares only with lengths of real paths); the order only decides how much is pruned early. A band
// of about one edge keeps the extra propagations small while giving each round a wavefront's worth of lists.
#include <algorithm>

#include "phase_timer.hpp"
#include "vtp_engine.hpp"

namespace exactgeo::detail {
namespace {

// Width of a band in mean edge lengths.
constexpr double kBandEdges = 1.0;

}  // namespace

void VtpEngine::run_vertex_sorted_in_bands(unsigned threads) {
  if (!pool_ || pool_->threads() != threads) pool_ = std::make_unique<WorkerPool>(threads);
  scratch_.assign(threads, ThreadScratch{});
  round_slot_.assign(mesh_.halfedges.size(), kNone);
  double total_length = 0;
  for (const HalfedgeGeometry& g : mesh_.halfedges) total_length += g.length;
  band_width_ = kBandEdges * total_length / static_cast<double>(std::max<std::size_t>(1, mesh_.halfedges.size()));

  while (!vertex_queue_.empty()) {
    update_cutoff();
    ++stats_.parallel_bands;
    ++iteration_;  // one iteration per band: all its faces are new to the traversed area
    const double band_end = vertex_queue_.top_key() + band_width_;
    band_.clear();
    do {
      std::uint32_t v;
      {
        const PhaseTimer timer(options_.collect_timings, stats_.queue_seconds);
        v = vertex_queue_.pop();
      }
      move_inside(v);
      band_.push_back(v);
    } while (!vertex_queue_.empty() && vertex_queue_.top_key() <= band_end);
    enclose_band();
    drain_in_rounds();
  }
  for (const ThreadScratch& s : scratch_) {
    stats_.pruning_seconds += s.stats.pruning_seconds;
    stats_.prime_propagations += s.stats.prime_propagations;
    stats_.secondary_propagations += s.stats.secondary_propagations;
    stats_.prime_merges += s.stats.prime_merges;
    stats_.secondary_merges += s.stats.secondary_merges;
  }
}

// The band's vertices emit and their faces join the traversed area, as enclose_vertex does for one vertex.
// Their emissions are collected in parallel, each with its vertex's distance as the band found it, while one
// task enters the band's faces in the band's order (collecting reads nothing entering writes). Then the
// emissions are applied in the band's order, onto faces already entered; one lowered by an earlier vertex of
// the band emits again at the lower distance (paper Section 5.2, third scenario), like any pseudo-source
// inside.
void VtpEngine::enclose_band() {
  for (ThreadScratch& s : scratch_) s.emitted.clear();
  band_emissions_.resize(band_.size());
  {
    const PhaseTimer timer(options_.collect_timings, stats_.parallel_seconds);
    pool_->run(band_.size() + 1, [this](std::size_t i, unsigned thread) {
      if (i == 0) {
        for (const std::uint32_t v : band_) enter_faces_of(v);
      } else {
        collect_in_band(i - 1, thread);
      }
    });
  }
  for (std::size_t i = 0; i < band_.size(); ++i) {
    const BandEmission& e = band_emissions_[i];
    if (!e.emits) continue;
    const Emission& emitted = scratch_[e.thread].emitted;
    apply_emission(band_[i], e.at, std::span(emitted.offers).subspan(e.offers_begin, e.offers_end - e.offers_begin),
                   std::span(emitted.windows).subspan(e.windows_begin, e.windows_end - e.windows_begin));
  }
}

void VtpEngine::collect_in_band(std::size_t i, unsigned thread) {
  const std::uint32_t v = band_[i];
  BandEmission& e = band_emissions_[i];
  e.emits = bends_paths(v) && distance_[v] <= cutoff_;
  if (!e.emits) return;
  Emission& emitted = scratch_[thread].emitted;
  e.thread = thread;
  e.at = distance_[v];
  e.offers_begin = static_cast<std::uint32_t>(emitted.offers.size());
  e.windows_begin = static_cast<std::uint32_t>(emitted.windows.size());
  collect_emission(v, emitted);
  e.offers_end = static_cast<std::uint32_t>(emitted.offers.size());
  e.windows_end = static_cast<std::uint32_t>(emitted.windows.size());
}

void VtpEngine::drain_in_rounds() {
  while (true) {
    while (!emit_queue_.empty()) emit_lowered_pseudo_source();
    lists_.note_peak();
    if (pending_.empty()) return;
    round_.swap(pending_);
    ++stats_.parallel_rounds;
    stats_.parallel_round_lists += round_.size();
    pending_.clear();
    for (std::uint32_t i = 0; i < round_.size(); ++i) {
      scheduled_[round_[i]] = 0;
      round_slot_[round_[i]] = i;
    }

    // 1. Every list crosses its face, in parallel.
    for (ThreadScratch& s : scratch_)
      for (std::vector<Window>& crossed : s.crossed) crossed.clear();
    crossings_.resize(round_.size());
    round_flags_.resize(round_.size());
    apex_offers_.resize(round_.size());
    {
      const PhaseTimer parallel(options_.collect_timings, stats_.parallel_seconds);
      const PhaseTimer timer(options_.collect_timings, stats_.window_propagation_seconds);
      pool_->run(round_.size(), [this](std::size_t i, unsigned thread) { cross_in_round(i, thread); });
    }

    // 2. In the round's order: the distances the lists found at their opposite corners, and targets.
    const bool has_targets = !face_target_offsets_.empty();
    for (std::uint32_t i = 0; i < round_.size(); ++i) {
      // Distances only fall: a list that did not lower its opposite corner at the round's start cannot now.
      if (round_flags_[i] & kLowersApex) relax(mesh_.apex(round_[i]), apex_offers_[i].distance, apex_offers_[i].arrival);
      if (has_targets && (round_flags_[i] & kCrossed)) {
        evaluate_targets(round_[i], lists_.view(round_[i]));
        lists_.clear(round_[i], 0);
      }
    }

    // 3. Each edge reached joins its arrivals, in parallel over the edges.
    {
      const PhaseTimer timer(options_.collect_timings, stats_.parallel_seconds);
      pool_->run(round_.size(), [this](std::size_t i, unsigned thread) { join_in_round(i, thread); });
    }
    lists_.note_peak();

    // 4. The joined lists inside the traversed area move on in the next round, in the order they were reached.
    for (std::uint32_t i = 0; i < round_.size(); ++i) {
      const std::uint32_t h = round_[i];
      round_slot_[h] = kNone;
      if (round_flags_[i] & kScheduleToAC) schedule(mesh_.twin[prev_halfedge(h)]);
      if (round_flags_[i] & kScheduleToBC) schedule(mesh_.twin[next_halfedge(h)]);
    }
  }
}

// Round phase 1 for the i-th list of the round: crosses it into this thread's buffers, and frees it unless
// its targets still need it.
void VtpEngine::cross_in_round(std::size_t i, unsigned thread) {
  ThreadScratch& scratch = scratch_[thread];
  RoundCrossing& c = crossings_[i];
  const std::uint32_t h = round_[i];
  c = RoundCrossing{thread, false, {}, {Handover{kNone, Joining::inside, 0}, Handover{kNone, Joining::inside, 0}}};
  round_flags_[i] = 0;
  if (lists_.empty(h)) return;
  if (i + 1 < round_.size()) prefetch_crossing(round_[i + 1]);  // most often this thread's next item
  prefetch_destinations(h);
  const std::span<const Window> incoming = list_to_cross(h, thread, scratch.stats);
  const std::array<std::uint32_t, 2> sides = {prev_halfedge(h), next_halfedge(h)};
  const std::array<std::uint32_t, 2> origins = {mesh_.tail(h), mesh_.head(h)};
  for (std::uint32_t side = 0; side < 2; ++side) c.begin[side] = static_cast<std::uint32_t>(scratch.crossed[side].size());
  ApexReach reach;
  Arrival at_apex;
  const std::uint64_t propagations =
      cross_list(h, incoming, scratch.splits, scratch.crossed[0], scratch.crossed[1], reach, at_apex);
  c.prime = face_visited_at_[face_of(h)] == iteration_;
  (c.prime ? scratch.stats.prime_propagations : scratch.stats.secondary_propagations) += propagations;
  round_flags_[i] = kCrossed;
  if (reach.distance < distance_[mesh_.apex(h)]) {
    round_flags_[i] |= kLowersApex;
    apex_offers_[i] = {reach.distance, at_apex};
  }
  if (face_target_offsets_.empty()) lists_.clear(h, thread);
  for (std::uint32_t side = 0; side < 2; ++side) {
    std::vector<Window>& crossed = scratch.crossed[side];
    const std::span<Window> windows(crossed.data() + c.begin[side], crossed.size() - c.begin[side]);
    if (windows.empty()) continue;
    c.handover[side] = hand_over(sides[side], windows, origins[side], c.prime);
    crossed.resize(c.begin[side] + c.handover[side].count);  // the next crossing's windows follow the kept ones
  }
}

// Round phase 3 for the i-th list of the round: the edges its windows reached join them. An edge is reached
// only from the face behind it, by the lists on that face's two other halfedges; if both crossed in this
// round, the earlier one joins the arrivals of both, in the round's order, so that each edge is changed by
// one thread.
void VtpEngine::join_in_round(std::size_t i, unsigned thread) {
  const RoundCrossing& c = crossings_[i];
  const std::uint32_t h = round_[i];
  GeodesicStats& stats = scratch_[thread].stats;
  for (std::uint32_t side = 0; side < 2; ++side) {
    const std::uint32_t edge = c.handover[side].edge;
    if (edge == kNone) continue;
    const std::uint32_t partner = round_slot_[side == 0 ? next_halfedge(h) : prev_halfedge(h)];
    const bool partner_delivers = partner != kNone && crossings_[partner].handover[1 - side].edge == edge;
    if (partner_delivers && partner < i) continue;
    std::array<RoundDelivery, 2> deliveries = {RoundDelivery{static_cast<std::uint32_t>(i), side}, RoundDelivery{partner, 1 - side}};
    const std::uint32_t count = partner_delivers ? 2 : 1;

    std::size_t size = lists_.view(edge).size(), added = 0;
    for (std::uint32_t k = 0; k < count; ++k) {
      const Handover& to = crossings_[deliveries[k].crossing].handover[deliveries[k].side];
      if (to.joining != Joining::inside && size + added > 0)
        ++(crossings_[deliveries[k].crossing].prime ? stats.prime_merges : stats.secondary_merges);
      added += to.count;
    }
    const std::span<Window> list = lists_.extend(edge, added, thread);
    for (std::uint32_t k = 0; k < count; ++k) {
      const RoundCrossing& from = crossings_[deliveries[k].crossing];
      const Handover& to = from.handover[deliveries[k].side];
      const Window* arriving = scratch_[from.thread].crossed[deliveries[k].side].data() + from.begin[deliveries[k].side];
      std::copy(arriving, arriving + to.count, list.begin() + static_cast<std::ptrdiff_t>(size));
      size += to.count;
      join(list.first(size), to.count, to.joining);
    }
    if (size > 0 && face_visited_at_[face_of(edge)] != kNone) round_flags_[i] |= side == 0 ? kScheduleToAC : kScheduleToBC;
  }
}

}  // namespace exactgeo::detail
