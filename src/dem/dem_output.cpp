#include "dem/dem_output.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cstdio>

#include "core/error.hpp"
#include "io/vtk.hpp"
#include "dem/membrane/membrane_boundary.hpp"

namespace ff::dem {

void DemVtkWriter::open(const std::filesystem::path& dir, bool resume, double time, bool membrane) {
  dir_ = dir;
  std::filesystem::create_directories(dir);
  particles_.open(dir / "particles.pvd", resume, time);
  bonds_.open(dir / "bonds.pvd", resume, time);
  contacts_.open(dir / "contacts.pvd", resume, time);
  cracks_.open(dir / "cracks.pvd", resume, time);
  walls_.open(dir / "walls.pvd", resume, time);
  with_membrane_ = membrane;
  if (membrane) membrane_.open(dir / "membrane.pvd", resume, time);
}

namespace {
// A wall drawn as triangles: planes as squares of side `extent` centred on the sample axis,
// cylinders as 48 facets around.
void wall_triangles(const Wall& w, Real extent, const Vec3& centre, std::vector<Vec3>& pts, std::vector<std::int64_t>& tri) {
  const auto base = static_cast<std::int64_t>(pts.size());
  if (w.kind == Wall::Kind::Plane) {
    const Vec3 n = w.normal;
    const Vec3 u = (std::abs(n.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY()).cross(n).normalized();
    const Vec3 v = n.cross(u);
    const Vec3 c = centre - (centre - w.point).dot(n) * n;
    const Real h = 0.5 * extent;
    pts.push_back(c - h * u - h * v);
    pts.push_back(c + h * u - h * v);
    pts.push_back(c + h * u + h * v);
    pts.push_back(c - h * u + h * v);
    for (std::int64_t k : {0, 1, 2, 0, 2, 3}) tri.push_back(base + k);
  } else {
    const int m = 48;
    const Vec3 a = w.normal;
    const Vec3 u = (std::abs(a.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY()).cross(a).normalized();
    const Vec3 v = a.cross(u);
    const Vec3 c0 = w.point + (centre - w.point).dot(a) * a - 0.5 * extent * a;
    for (int k = 0; k < m; ++k) {
      const Real t = 2 * kPi * k / m;
      const Vec3 r = w.radius * (std::cos(t) * u + std::sin(t) * v);
      pts.push_back(c0 + r);
      pts.push_back(c0 + r + extent * a);
    }
    for (int k = 0; k < m; ++k) {
      const std::int64_t p0 = base + 2 * k, p1 = p0 + 1, q0 = base + 2 * ((k + 1) % m), q1 = q0 + 1;
      for (std::int64_t idx : {p0, q0, q1, p0, q1, p1}) tri.push_back(idx);
    }
  }
}
}  // namespace

void DemVtkWriter::write(const DemSystem& sys, long index, Real wall_extent) {
  const auto& P = sys.particles;
  const std::size_t n = P.size();
  const std::string tag = fmt::format("{:06d}", index);
  // Particles: every field of the declaration with a VTK name (particle_store.hpp).
  {
    std::vector<VtkArray> pd;
    ParticleStore::for_each_field([&](const auto& fd) {
      if (fd.vtk) pd.push_back(vtk_array(fd.vtk, std::span(P.*fd.member)));
    });
    const std::string f = "particles_" + tag + ".vtp";
    write_vtp(dir_ / f, P.pos, VtpCells{}, pd, {});
    particles_.add(sys.time, f);
  }
  // Intact bonds as lines with their normal force (tension > 0) and shear force.
  {
    std::vector<std::int64_t> conn;
    std::vector<double> fn, fs;
    std::vector<std::int32_t> pair;
    const auto& bl = sys.bond_loads();
    for (std::size_t b = 0; b < sys.bonds.i.size(); ++b) {
      if (sys.bonds.broken[b]) continue;
      conn.push_back(sys.bonds.i[b]);
      conn.push_back(sys.bonds.j[b]);
      const Vec3 d = (P.pos[sys.bonds.j[b]] - P.pos[sys.bonds.i[b]]).normalized();
      const Vec3& f = bl[b].f;
      fn.push_back(-f.dot(d));
      fs.push_back((f - f.dot(d) * d).norm());
      pair.push_back(sys.bonds.pair[b]);
    }
    const VtkArray cd[] = {vtk_array("normal_force", std::span<const double>(fn)),
                           vtk_array("shear_force", std::span<const double>(fs)),
                           vtk_array("group_pair", std::span<const std::int32_t>(pair))};
    const std::string f = "bonds_" + tag + ".vtp";
    write_vtp(dir_ / f, P.pos, VtpCells{VtpCells::Lines, conn}, {}, cd);
    bonds_.add(sys.time, f);
  }
  // Contact-force network: compressive contacts between sample particles as lines carrying the
  // normal force (use a Tube filter scaled by "normal_force" for force chains).
  {
    std::vector<std::int64_t> conn;
    std::vector<double> fn;
    const auto pi = sys.neighbors().first(), pj = sys.neighbors().second();
    const auto& pl = sys.pair_loads();
    for (std::size_t k = 0; k < pi.size(); ++k) {
      if (pl[k].f.squaredNorm() == 0) continue;
      if (static_cast<std::size_t>(std::max(pi[k], pj[k])) >= sample_particles_) continue;
      const Vec3 d = (P.pos[pj[k]] - P.pos[pi[k]]).normalized();
      conn.push_back(pi[k]);
      conn.push_back(pj[k]);
      fn.push_back(pl[k].f.dot(d));
    }
    const VtkArray cd[] = {vtk_array("normal_force", std::span<const double>(fn))};
    const std::string f = "contacts_" + tag + ".vtp";
    write_vtp(dir_ / f, P.pos, VtpCells{VtpCells::Lines, conn}, {}, cd);
    contacts_.add(sys.time, f);
  }
  // Cracks so far: one point each with its normal, size, mode (1 tensile, 2 shear) and time
  // (Glyph with discs oriented by "normal" and scaled by "size").
  {
    const auto& ev = sys.cracks.events;
    std::vector<Vec3> pos(ev.size()), nrm(ev.size());
    std::vector<double> size(ev.size()), t(ev.size());
    std::vector<std::int32_t> mode(ev.size()), ga(ev.size()), gb(ev.size());
    for (std::size_t k = 0; k < ev.size(); ++k) {
      pos[k] = ev[k].position;
      nrm[k] = ev[k].normal;
      size[k] = ev[k].size;
      t[k] = ev[k].time;
      mode[k] = ev[k].mode;
      ga[k] = std::min(ev[k].group_a, ev[k].group_b);
      gb[k] = std::max(ev[k].group_a, ev[k].group_b);
    }
    const VtkArray pd[] = {vtk_array("normal", std::span<const Vec3>(nrm)), vtk_array("size", std::span<const double>(size)),
                           vtk_array("mode", std::span<const std::int32_t>(mode)), vtk_array("time", std::span<const double>(t)),
                           vtk_array("group_a", std::span<const std::int32_t>(ga)),
                           vtk_array("group_b", std::span<const std::int32_t>(gb))};
    const std::string f = "cracks_" + tag + ".vtp";
    write_vtp(dir_ / f, pos, VtpCells{}, pd, {});
    cracks_.add(sys.time, f);
  }
  // Walls.
  {
    Vec3 centre = Vec3::Zero();
    for (std::size_t i = 0; i < n; ++i) centre += P.pos[i];
    if (n) centre /= static_cast<Real>(n);
    std::vector<Vec3> pts;
    std::vector<std::int64_t> tri;
    std::vector<std::int32_t> wid;
    for (std::size_t w = 0; w < sys.walls.size(); ++w) {
      if (!sys.walls[w].active) continue;
      const std::size_t before = tri.size();
      wall_triangles(sys.walls[w], wall_extent, centre, pts, tri);
      for (std::size_t k = before; k < tri.size(); k += 3) wid.push_back(static_cast<std::int32_t>(w));
    }
    const VtkArray cd[] = {vtk_array("wall", std::span<const std::int32_t>(wid))};
    const std::string f = "walls_" + tag + ".vtp";
    write_vtp(dir_ / f, pts, VtpCells{VtpCells::Triangles, tri}, {}, cd);
    walls_.add(sys.time, f);
  }
  if (const auto* mem = membrane_of(sys); with_membrane_ && mem) {
    const std::string f = "membrane_" + tag + ".vtp";
    mem->write_vtk(dir_ / f);
    membrane_.add(sys.time, f);
  }
}

void append_cracks_csv(const std::filesystem::path& csv, const CrackLog& log, const Materials& mat, std::size_t from) {
  std::FILE* f = std::fopen(csv.c_str(), from == 0 ? "w" : "a");
  if (!f) throw Error(fmt::format("cannot write '{}'", csv.string()));
  // Names end in their SI unit (size_m: the crack disc radius, the bond's); the normal is a unit vector.
  // id_a, id_b: the particles' global ids (the "id" of the VTK particle files), not array indices.
  if (from == 0) fmt::print(f, "time_s,x_m,y_m,z_m,nx,ny,nz,size_m,mode,group_a,group_b,id_a,id_b\n");
  for (std::size_t k = from; k < log.events.size(); ++k) {
    const auto& e = log.events[k];
    fmt::print(f, "{},{},{},{},{},{},{},{},{},{},{},{},{}\n", e.time, e.position.x(), e.position.y(), e.position.z(),
               e.normal.x(), e.normal.y(), e.normal.z(), e.size, e.mode == 1 ? "tensile" : "shear",
               mat.group_names[e.group_a], mat.group_names[e.group_b], e.i, e.j);
  }
  std::fclose(f);
}

}  // namespace ff::dem
