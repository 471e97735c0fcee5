// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "kiseki/grid/occupancy_grid.hpp"
#include "kiseki/models/sensor_model.hpp"

namespace kiseki {

/// The four counts behind the space observation model, over cells inside the field of view.
struct SpaceObservationCounts {
  int penetrating = 0;    ///< free in L, occupied in the map
  int map_occupied = 0;   ///< occupied in the map (in view)
  int intruding = 0;      ///< occupied in L, free in the map
  int map_free = 0;       ///< free in the map (in view)
  double penetration_ratio() const;  ///< percent
  double intrusion_ratio() const;    ///< percent
};

struct SpaceObservationParams {
  double sigma_penetration = 10.0;  ///< percent (the thesis)
  double sigma_intrusion = 130.0;   ///< percent (the thesis)
  double heading_step_deg = 1.0;    ///< bin width of the pre-rotated local maps
  std::int8_t occupied_threshold = 65;  ///< map cells >= this are occupied; 0..free_max free
  std::int8_t free_max = 19;
  /// Proposal 1 of the thesis: compare L with the map the particle should observe, in which
  /// every map cell hidden from the sensor behind an occupied cell counts as occupied.
  bool occlusion_aware = false;
  void validate() const;
};

/// The teaching-and-playback thesis' space observation model (sec. 3.3): for a particle, the
/// map cut out at its pose (m_i) is compared with the local map L:
///   penetration ratio = 100 |free in L and occupied in m_i| / |occupied in m_i|,
///   intrusion ratio   = 100 |occupied in L and free in m_i| / |free in m_i|,
///   likelihood = N(pen; 0, sigma_p) N(intr; 0, sigma_i) (unnormalised Gaussians),
/// counting only cells inside L's field of view.
///
/// Speed: instead of cutting a rotated m_i out of the map for every particle, L is rotated once
/// per heading bin into the map's axes (lazily, then cached until the next local map) and
/// stored as bit rows; a particle then costs a few AND + popcount per row against the map's bit
/// rows at an integer cell offset. Discretisation: heading to the nearest bin, position to the
/// map cell containing the particle; each rotated cell takes the L cell under its centre.
/// Occlusion-aware (proposal 1): the window of map cells around the particle's cell is seen
/// from that cell's centre along one straight segment to the centre of every cell on the
/// window's border (4 (span - 1) segments, which together pass through every cell of the
/// window). A segment sees the cells it passes through, in order, up to and including the first
/// occupied one; where it passes exactly through a cell corner it also sees the two cells
/// touching that corner on either side, and stops there if both are occupied (a wall whose
/// cells touch only at corners still hides what is behind it). Cells outside the map are never
/// occupied. Each segment is walked cell by cell (Amanatides-Woo) with its boundary crossings
/// compared exactly in integers, so corners are found without rounding. Visibility depends on
/// the cell only, so it is cached per cell (bounded in size, thread-safe) and shared by the
/// particles in it. The numpy reference is kiseki.models.visibility_reference.
class SpaceObservationModel : public SensorModel {
 public:
  SpaceObservationModel(const OccupancyGrid& map, const SpaceObservationParams& params = {});
  ~SpaceObservationModel();
  SpaceObservationModel(SpaceObservationModel&&) noexcept;
  SpaceObservationModel& operator=(SpaceObservationModel&&) noexcept;

  /// A new local map (robot frame, centred on the robot). Clears the rotation cache.
  void set_local_map(const OccupancyGrid& local);
  SpaceObservationCounts counts(const Pose2& pose) const;
  double likelihood(const Pose2& pose) const;
  /// Likelihoods of n particles (poses row-major n x 3).
  void likelihoods(const double* poses, std::size_t n, double* out) const;
  /// SensorModel: log of likelihood() per pose (-inf where it is 0).
  void log_likelihoods(const Pose2* poses, std::size_t n, double* out) const override;
  /// SensorModel: 1 - the share of the map's occupied cells in view that the local map sees as
  /// free (1 - penetration ratio / 100, at least 0); 0 off the map's free cells; NaN when no
  /// occupied map cell is in view.
  double agreement(const Pose2& pose) const override;

  /// The local map rotated to heading bin k, as the map-aligned cells it would overlay (int8,
  /// -1 outside view), for tests and the numpy reference.
  OccupancyGrid rotated_local_map(int bin) const;
  int bin_of(double heading) const;
  /// The window of map cells around the particle's cell, 1 where visible from it, else 0
  /// (occlusion-aware model only; for tests and the numpy reference).
  OccupancyGrid visibility(const Pose2& pose) const;
  int bins() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace kiseki
