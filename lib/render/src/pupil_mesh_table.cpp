#include "pupil_mesh_table.h"

#include <algorithm>
#include <cmath>
#include <unordered_map>

#include "lensmith/core/units.h"

namespace lensmith::render_detail {

namespace {

constexpr std::array<int, 9> kSectorSteps{8, 12, 16, 24, 32, 48, 64, 96, 128};
constexpr std::array<int, 8> kRingSteps{1, 2, 3, 4, 6, 8, 12, 16};
constexpr std::array<int, 5> kGridSteps{4, 8, 16, 32, 64};
// Aperture::mesh's sector count, which grids do not use (it must be at least 3).
constexpr int kGridSectorsUnused = 4;

template <std::size_t N>
int step_index(const std::array<int, N>& steps, double wanted) {
  for (std::size_t i = 0; i < N; ++i) {
    if (steps[i] >= wanted) return static_cast<int>(i);
  }
  return static_cast<int>(N) - 1;
}

PupilMeshTable::Edges mesh_edges(const PupilMesh& mesh) {
  PupilMeshTable::Edges out;
  std::unordered_map<std::uint64_t, std::uint32_t> index;
  index.reserve(mesh.triangles.size() * 2);
  for (const PupilTriangle& t : mesh.triangles) {
    const std::array<int, 3> v{t.a, t.b, t.c};
    std::array<std::uint32_t, 3> of{};
    std::array<std::int8_t, 3> direction{};
    for (std::size_t k = 0; k < 3; ++k) {
      const auto p = static_cast<std::uint32_t>(v[k]), q = static_cast<std::uint32_t>(v[(k + 1) % 3]);
      const std::uint32_t lo = std::min(p, q), hi = std::max(p, q);
      const auto [it, added] = index.try_emplace((std::uint64_t{lo} << 32) | hi, static_cast<std::uint32_t>(out.ends.size()));
      if (added) out.ends.push_back({lo, hi});
      of[k] = it->second;
      direction[k] = p == lo ? std::int8_t{1} : std::int8_t{-1};
    }
    out.of_triangle.push_back(of);
    out.direction.push_back(direction);
  }
  return out;
}

}  // namespace

PupilMeshTable::PupilMeshTable(const Aperture& aperture) : aperture_(&aperture) {
  const std::size_t count = aperture.kind() == Aperture::Kind::Mask ? kGridSteps.size() : kRingSteps.size() * kSectorSteps.size();
  meshes_.resize(count);
  edges_.resize(count);
  built_ = std::make_unique<std::once_flag[]>(count);
  if (aperture.kind() == Aperture::Kind::Mask) return;
  for (int sectors : kSectorSteps) {
    outlines_.push_back(aperture.outline(aperture.kind() == Aperture::Kind::Blades ? aperture.blade_count() : sectors));
    dense_outlines_.push_back(aperture.outline(sectors));
    Directions d;
    const std::vector<PupilPoint>& outline = dense_outlines_.back();
    for (std::size_t j = 0; j < outline.size(); ++j) {
      const PupilPoint& q = outline[j];
      const PupilPoint& next = outline[(j + 1) % outline.size()];
      const double len = std::hypot(q.x, q.y);
      d.ux.push_back(q.x / len);
      d.uy.push_back(q.y / len);
      d.inverse_length.push_back(1.0 / len);
      d.half_cross.push_back(0.5 * (q.x * next.y - next.x * q.y));
      d.area += d.half_cross.back();
    }
    dense_directions_.push_back(std::move(d));
  }
}

const PupilMesh& PupilMeshTable::mesh(int index) const {
  const auto i = static_cast<std::size_t>(index);
  std::call_once(built_[i], [&] {
    if (aperture_->kind() == Aperture::Kind::Mask) {
      meshes_[i] = aperture_->mesh(kGridSteps[i], kGridSectorsUnused);
    } else {
      meshes_[i] = aperture_->mesh(kRingSteps[i / kSectorSteps.size()], kSectorSteps[i % kSectorSteps.size()]);
    }
    edges_[i] = mesh_edges(meshes_[i]);
  });
  return meshes_[i];
}

const PupilMeshTable::Edges& PupilMeshTable::edges(int index) const {
  mesh(index);
  return edges_[static_cast<std::size_t>(index)];
}

int PupilMeshTable::sector_step(double diameter_px) {
  // A polygon of S sectors inscribed in a circle of diameter d departs from it by d (1 - cos(pi/S)) / 2
  // ~ d pi^2 / (4 S^2): below 0.1 px for S >= pi sqrt(2.5 d).
  return step_index(kSectorSteps, kPi * std::sqrt(2.5 * std::max(diameter_px, 0.0)));
}

int PupilMeshTable::polar_mesh(double rings, int sector_step) {
  return step_index(kRingSteps, rings) * static_cast<int>(kSectorSteps.size()) + sector_step;
}

int PupilMeshTable::sector_step_of_mesh(int mesh_index) { return mesh_index % static_cast<int>(kSectorSteps.size()); }

int PupilMeshTable::grid_mesh(double cells) { return step_index(kGridSteps, cells); }

}  // namespace lensmith::render_detail
