#include "dem/membrane/membrane_boundary.hpp"

#include "core/error.hpp"
#include "io/checkpoint.hpp"

namespace ff {
template <> struct is_checkpoint_pod<dem::ContactState> : std::true_type {};
}  // namespace ff

namespace ff::dem {

void MembraneBoundary::search(const DemSystem& sys, Real travel) {
  m_.find_candidates(sys.particles.pos, sys.particles.radius, sys.settings.skin);
  built_at_travel_ = travel;
  ++builds_;
}

void MembraneBoundary::rebuild_candidates(const DemSystem& sys) {
  Real travel = 0;
  sys.neighbors().needs_rebuild(sys.particles.pos, 0, &travel);
  search(sys, travel);
}

void MembraneBoundary::update_neighbors(const DemSystem& sys, bool rebuilt, Real travel) {
  if (rebuilt) {
    search(sys, 0);
    return;
  }
  // A particle-element pair further apart than the particle's radius + skin at the build can
  // touch only once the particle's travel plus the element's (each vertex's travel bounds that
  // of every point of the triangle) reach the skin.
  const Real dt = sys.settings.dt;
  const Real particle_travel = travel + built_at_travel_;
  if (particle_travel + m_.motion_since_build() + m_.max_step_motion(dt) > sys.settings.skin) search(sys, travel);
}

void MembraneBoundary::compute_forces(const DemSystem& sys) {
  const auto& P = sys.particles;
  const MembraneParticles p{P.pos, P.vel, P.omega, P.radius, P.group};
  const auto& mat = sys.materials;
  mat.with_contact_law([&]<class Law>(std::type_identity<Law>) {
    m_.compute_forces<Law>(p, std::span<const typename Law::Params>(mat.contact_params<Law>()), mat.groups(), sys.settings.dt);
  });
}

void MembraneBoundary::after_integrate(const DemSystem& sys) {
  m_.move(sys.settings.dt, sys.walls[bottom_wall_].point.z(), sys.walls[top_wall_].point.z());
}

void MembraneBoundary::save(CheckpointWriter& w, const DemSystem&) const {
  const auto x = m_.vertices(), v = m_.vertex_velocities();
  w.put("dem.membrane.x", std::vector<Vec3>(x.begin(), x.end()));
  w.put("dem.membrane.v", std::vector<Vec3>(v.begin(), v.end()));
  w.put_value("dem.membrane.pressure", m_.settings().pressure);
  // Shear history of the element contacts (frictional membranes depend on it).
  const auto cp = m_.candidate_particles(), ce = m_.candidate_elements();
  const auto cs = m_.contact_states();
  w.put("dem.membrane.cand_p", std::vector<Index>(cp.begin(), cp.end()));
  w.put("dem.membrane.cand_e", std::vector<Index>(ce.begin(), ce.end()));
  w.put("dem.membrane.state", std::vector<ContactState>(cs.begin(), cs.end()));
}

void MembraneBoundary::load(CheckpointReader& r, const DemSystem& sys) {
  // The membrane is built by the driver from its settings before load_dem(); its vertices come
  // back here, its candidates are searched again and every candidate found again gets its
  // contact history back (both lists are sorted by particle, then element).
  if (!r.has("dem.membrane.x"))
    throw InputError("checkpoint holds no flexible membrane, but the scenario has one; resume with the scenario it was written with");
  std::vector<Vec3> x, v;
  r.get("dem.membrane.x", x);
  r.get("dem.membrane.v", v);
  m_.restore_vertices(x, v);
  m_.set_pressure(r.get_value<Real>("dem.membrane.pressure"));
  rebuild_candidates(sys);
  if (r.has("dem.membrane.state")) {
    std::vector<Index> op, oe;
    std::vector<ContactState> os;
    r.get("dem.membrane.cand_p", op);
    r.get("dem.membrane.cand_e", oe);
    r.get("dem.membrane.state", os);
    const auto np = m_.candidate_particles(), ne = m_.candidate_elements();
    const auto ns = m_.contact_states();
    std::size_t k = 0;
    for (std::size_t c = 0; c < np.size(); ++c) {
      while (k < op.size() && (op[k] < np[c] || (op[k] == np[c] && oe[k] < ne[c]))) ++k;
      if (k < op.size() && op[k] == np[c] && oe[k] == ne[c]) ns[c] = os[k];
    }
  }
}

FlexibleMembrane& attach_membrane(DemSystem& sys, const MembraneSettings& s, int bottom_wall, int top_wall) {
  auto& b = sys.add_boundary(std::make_unique<MembraneBoundary>(s, bottom_wall, top_wall));
  return static_cast<MembraneBoundary&>(b).membrane();
}

MembraneBoundary* membrane_boundary(const DemSystem& sys) {
  for (const auto& b : sys.boundaries())
    if (auto* m = dynamic_cast<MembraneBoundary*>(b.get())) return m;
  return nullptr;
}

}  // namespace ff::dem
