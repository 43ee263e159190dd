// Built with -UNDEBUG (includes Simbody; docs/design.md section 4).
#include "hrp2_bridge/sim/dynamics_simulation.h"

#include <Simbody.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <map>
#include <set>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "hrp2_bridge/bridge_config.h"
#include "hrp2_bridge/stabilizer_schedule.h"
#include "planner/check/quasi_static.h"
#include "planner/model/kinematics.h"

namespace acyclic::hrp2 {

namespace {

SimTK::Vec3 toSimVec(const Eigen::Vector3d& v) { return SimTK::Vec3(v.x(), v.y(), v.z()); }
Eigen::Vector3d toEigen(const SimTK::Vec3& v) { return Eigen::Vector3d(v[0], v[1], v[2]); }

SimTK::Rotation toSimRot(const Eigen::Matrix3d& R) {
  SimTK::Mat33 m;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) m(i, j) = R(i, j);
  return SimTK::Rotation(m);
}
SimTK::Transform toSim(const Eigen::Isometry3d& T) { return SimTK::Transform(toSimRot(T.linear()), toSimVec(T.translation())); }

Eigen::Isometry3d toEigen(const SimTK::Transform& X) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) T.linear()(i, j) = X.R().asMat33()(i, j);
  T.translation() = toEigen(X.p());
  return T;
}

// The floor: the lowest surfaces facing up; every spot may touch them.
std::vector<int> floorSurfaces(const Scene& scene) {
  std::vector<int> up;
  double lowest = std::numeric_limits<double>::infinity();
  for (int s = 0; s < static_cast<int>(scene.surfaces().size()); ++s) {
    const Surface& sf = scene.surfaces()[s];
    if (sf.frame.linear().col(2).z() < 0.999) continue;
    lowest = std::min(lowest, sf.frame.translation().z());
    up.push_back(s);
  }
  std::vector<int> out;
  for (int s : up)
    if (scene.surfaces()[s].frame.translation().z() <= lowest + 1e-9) out.push_back(s);
  return out;
}

// The spot-surface pairs the simulation gives spheres: those given (the
// trajectory's, contactPairs) and every spot on the floor.
std::set<std::pair<int, int>> spotSurfaces(const Scene& scene, const RobotModel& m,
                                           const std::vector<std::pair<int, int>>& pairs) {
  std::set<std::pair<int, int>> all(pairs.begin(), pairs.end());
  for (int f : floorSurfaces(scene))
    for (int sp = 0; sp < static_cast<int>(m.spots().size()); ++sp) all.insert({sp, f});
  return all;
}

// A collision shape as contact spheres (centre in its link's frame, radius)
// that touch a plane where the shape does: a box's corners (spheres of
// `small` radius, or the box's half thickness where it is thinner, inset so
// that they touch the box's faces' planes), a capsule's two ends, a sphere,
// a cylinder's two rims (eight each, one where the cylinder is thinner than
// the spheres). Coincident centres are made once.
std::vector<std::pair<Eigen::Vector3d, double>> shapeSpheres(const CollisionShape& sh, double small) {
  std::vector<std::pair<Eigen::Vector3d, double>> out;
  auto add = [&out](const Eigen::Vector3d& c, double r) {
    for (const auto& [o, ro] : out)
      if ((o - c).norm() < 1e-12 && ro == r) return;
    out.push_back({c, r});
  };
  switch (sh.kind) {
    case CollisionShape::Kind::Box: {
      const double r = std::min(small, 0.5 * sh.size.minCoeff());
      const Eigen::Vector3d h = 0.5 * sh.size - Eigen::Vector3d::Constant(r);
      for (int i = 0; i < 8; ++i)
        add(sh.pose * Eigen::Vector3d((i & 1 ? 1 : -1) * h.x(), (i & 2 ? 1 : -1) * h.y(), (i & 4 ? 1 : -1) * h.z()), r);
      break;
    }
    case CollisionShape::Kind::Capsule:
      for (double z : {-0.5 * sh.length, 0.5 * sh.length}) add(sh.pose * Eigen::Vector3d(0, 0, z), sh.radius);
      break;
    case CollisionShape::Kind::Sphere:
      add(sh.pose.translation(), sh.radius);
      break;
    case CollisionShape::Kind::Cylinder: {
      const double r = std::min({small, sh.radius, 0.5 * sh.length});
      const double rim = sh.radius - r, z = 0.5 * sh.length - r;
      for (double zz : {-z, z})
        for (int k = 0; k < 8; ++k)
          add(sh.pose * Eigen::Vector3d(rim * std::cos(k * M_PI / 4), rim * std::sin(k * M_PI / 4), zz), r);
      break;
    }
  }
  return out;
}

// How deep below a surface a sphere still touches it: deeper than a
// sphere's compression under any load here, shallower than the obstacles.
constexpr double kSlab = 0.02;  // m

// Simbody's half-space is unbounded and it has no tracker for a sphere
// against a brick: this is its HalfSpaceSphere tracker (Hertz contact, so
// the Hunt-Crossley generator applies) for a scene surface, a plane bounded
// by its polygon and by a slab below it. A sphere whose centre projects
// outside the polygon, or lies deeper than the slab, does not touch it (a
// foot beside the chair's seat, a hand under the table). A sphere larger
// than the spots' (a capsule's end, body contacts) touches only while it is
// at most the slab plus a spot sphere's radius deep: its centre may be above
// the plane while most of it is inside the obstacle (a shank under the
// seat's front edge), which is no contact with the surface's face.
class SurfaceSphereTracker : public SimTK::ContactTracker::HalfSpaceSphere {
 public:
  struct Face {
    SimTK::Transform X_GH;        // the half-space's frame (x into the obstacle)
    Eigen::Isometry3d world_to_surface;
    ConvexPolygon polygon;
  };
  SurfaceSphereTracker(std::vector<Face> faces, double slab, double small)
      : faces_(std::move(faces)), slab_(slab), small_(small) {}
  bool trackContact(const SimTK::Contact& prior, const SimTK::Transform& X_GH, const SimTK::ContactGeometry& half,
                    const SimTK::Transform& X_GS, const SimTK::ContactGeometry& sphere, SimTK::Real cutoff,
                    SimTK::Contact& current) const override {
    for (const Face& f : faces_) {
      if ((f.X_GH.p() - X_GH.p()).norm() > 1e-9 || (f.X_GH.R().asMat33() - X_GH.R().asMat33()).norm() > 1e-9) continue;
      const Eigen::Vector3d c = f.world_to_surface * toEigen(X_GS.p());
      const double r = SimTK::ContactGeometry::Sphere::getAs(sphere).getRadius();
      if (!f.polygon.contains(c.head<2>()) || c.z() < -slab_ || (r > small_ && r - c.z() > slab_ + small_)) {
        current.clear();
        return true;
      }
      break;
    }
    return HalfSpaceSphere::trackContact(prior, X_GH, half, X_GS, sphere, cutoff, current);
  }

 private:
  std::vector<Face> faces_;
  double slab_, small_;
};

}  // namespace

void DynamicsOptions::validate() const {
  auto positive = [](double v, const char* name) {
    if (!(v > 0) || !std::isfinite(v)) throw std::invalid_argument(std::string(name) + " must be positive (got " + std::to_string(v) + ")");
  };
  positive(full_torque_error, "full_torque_error");
  positive(damping_ratio, "damping_ratio");
  positive(sphere_radius, "sphere_radius");
  positive(stiffness, "stiffness");
  positive(transition_velocity, "transition_velocity");
  positive(accuracy, "accuracy");
  positive(max_step, "max_step");
  positive(slip_bound, "slip_bound");
  positive(fall_height, "fall_height");
  positive(fall_tilt, "fall_tilt");
  positive(base_bound, "base_bound");
  if (!(dissipation >= 0)) throw std::invalid_argument("dissipation must be >= 0");
  if (integrator != "rk-merson" && integrator != "rk3" && integrator != "semi-explicit-euler2" && integrator != "cpodes")
    throw std::invalid_argument("integrator must be cpodes, semi-explicit-euler2, rk-merson or rk3 (got " + integrator + ")");
  if (!(settle >= 0)) throw std::invalid_argument("settle must be >= 0");
  if (!(body_contact_range >= 0) || !std::isfinite(body_contact_range))
    throw std::invalid_argument("body_contact_range must be >= 0 (got " + std::to_string(body_contact_range) + ")");
  stabilizer_options.validate();
}

const char* toString(SimulationReport::Verdict v) {
  switch (v) {
    case SimulationReport::Verdict::Executed: return "executed";
    case SimulationReport::Verdict::Fell: return "fell";
    case SimulationReport::Verdict::Slipped: return "slipped";
  }
  return "?";
}

std::vector<std::pair<int, int>> contactPairs(const Trajectory& tr) {
  std::set<std::pair<int, int>> s;
  for (const auto& p : tr.phases)
    for (const auto& c : p.contacts) s.insert({c.spot, c.surface});
  return {s.begin(), s.end()};
}

std::vector<std::pair<int, int>> bodyContactPairs(const Scenario& sc, const Trajectory& tr,
                                                  const DynamicsOptions& options) {
  const double range = options.body_contact_range;
  const RobotModel& m = *sc.robot;
  const auto& surfaces = sc.scene->surfaces();
  // The surfaces each link's spots meet: modelled by the spots.
  std::set<std::pair<int, int>> spotted;
  for (const auto& [sp, sf] : spotSurfaces(*sc.scene, m, contactPairs(tr))) spotted.insert({m.spots()[sp].link, sf});
  std::vector<Eigen::Isometry3d> to_surface;
  for (const Surface& sf : surfaces) to_surface.push_back(sf.frame.inverse());
  std::vector<std::vector<std::pair<Eigen::Vector3d, double>>> spheres(m.numLinks());
  for (int l = 0; l < m.numLinks(); ++l)
    for (const CollisionShape& sh : m.links()[l].shapes)
      for (const auto& sp : shapeSpheres(sh, options.sphere_radius)) spheres[l].push_back(sp);
  std::set<std::pair<int, int>> found;
  Kinematics kin(sc.robot);
  const int n = static_cast<int>(tr.samples.size());
  for (int k = 0; k < n; ++k) {
    const bool phase_start = k > 0 && tr.samples[k].phase != tr.samples[k - 1].phase;
    if (k % 10 != 0 && k != n - 1 && !phase_start) continue;
    kin.setConfiguration(tr.samples[k].q);
    for (int l = 0; l < m.numLinks(); ++l) {
      if (spheres[l].empty()) continue;
      const Eigen::Isometry3d X = kin.linkPose(l);
      for (int sf = 0; sf < static_cast<int>(surfaces.size()); ++sf) {
        if (spotted.count({l, sf}) || found.count({l, sf})) continue;
        for (const auto& [c, r] : spheres[l]) {
          const Eigen::Vector3d p = to_surface[sf] * (X * c);
          if (p.z() - r < range && p.z() > -kSlab && surfaces[sf].polygon.contains(p.head<2>())) {
            found.insert({l, sf});
            break;
          }
        }
      }
    }
  }
  return {found.begin(), found.end()};
}

// ---------------------------------------------------------------------------

// The servo's reference: linear in time from (t0, q0, dq0) to (t1, q1, dq1),
// held after t1. Continuous in time, so a new segment that starts where the
// last one is at the integrator's time leaves the integration consistent.
struct Reference {
  double t0 = 0, t1 = 0;
  Eigen::VectorXd q0, dq0, q1, dq1;
  void at(double t, Eigen::VectorXd& q, Eigen::VectorXd& dq) const {
    const double s = t1 > t0 ? std::clamp((t - t0) / (t1 - t0), 0.0, 1.0) : 1.0;
    q = q0 + s * (q1 - q0);
    dq = dq0 + s * (dq1 - dq0);
  }
};

struct Sphere {
  int spot = -1, surface = -1;
  int body = -1;  // a body sphere (spot -1): its index in the body pairs
};

struct DynamicsSimulator::Impl {
  std::shared_ptr<const RobotModel> robot;
  std::shared_ptr<const Scene> scene;
  DynamicsOptions opt;
  SimTK::MultibodySystem system;
  SimTK::SimbodyMatterSubsystem matter{system};
  SimTK::GeneralForceSubsystem forces{system};
  SimTK::ContactTrackerSubsystem tracker{system};
  SimTK::CompliantContactSubsystem contact{system, tracker};
  std::vector<SimTK::MobilizedBodyIndex> link_mobod;
  std::vector<int> q_index, u_index;  // per controller joint
  Eigen::VectorXd kp, kd, effort;
  Reference ref;
  std::map<int, Sphere> sphere_of_surface;  // tracker ContactSurfaceIndex -> sphere
  std::vector<std::pair<int, std::pair<SimTK::MobilizedBodyIndex, int>>> sphere_bodies;  // pending index lookup
  SimTK::State state;
  std::unique_ptr<SimTK::Integrator> integ;

  // PD servo toward the reference, torque clamped to the effort limit: a
  // position-controlled joint whose motor driver runs far faster than the
  // controller's 200 Hz, so it acts continuously on the streamed reference.
  class Servo : public SimTK::Force::Custom::Implementation {
   public:
    explicit Servo(const Impl& s) : s_(s) {}
    void calcForce(const SimTK::State& st, SimTK::Vector_<SimTK::SpatialVec>&, SimTK::Vector_<SimTK::Vec3>&,
                   SimTK::Vector& mobility) const override {
      Eigen::VectorXd q, dq;
      s_.ref.at(st.getTime(), q, dq);
      const SimTK::Vector& Q = st.getQ();
      const SimTK::Vector& U = st.getU();
      for (int j = 0; j < q.size(); ++j) {
        const double tau = s_.kp[j] * (q[j] - Q[s_.q_index[j]]) + s_.kd[j] * (dq[j] - U[s_.u_index[j]]);
        mobility[s_.u_index[j]] += std::clamp(tau, -s_.effort[j], s_.effort[j]);
      }
    }
    SimTK::Real calcPotentialEnergy(const SimTK::State&) const override { return 0; }

   private:
    const Impl& s_;
  };

  int body_pairs = 0;

  Impl(const Scenario& sc, const Configuration& start, const DynamicsOptions& o,
       const std::vector<std::pair<int, int>>& pairs, const std::vector<std::pair<int, int>>& bodies)
      : robot(sc.robot), scene(sc.scene), opt(o), body_pairs(static_cast<int>(bodies.size())) {
    opt.validate();
    const RobotModel& m = *robot;
    const int n = m.numJoints();
    // Joint frames: at the zero configuration every joint angle is zero, so
    // each parent-to-child link transform is the joint's placement.
    Kinematics zero(robot);
    zero.setConfiguration(m.zeroConfiguration());
    auto massProps = [](const LinkInfo& l) {
      const Eigen::Vector3d& c = l.com;
      const Eigen::Matrix3d Io = l.inertia + l.mass * (c.squaredNorm() * Eigen::Matrix3d::Identity() - c * c.transpose());
      SimTK::Mat33 I;
      for (int i = 0; i < 3; ++i)
        for (int k = 0; k < 3; ++k) I(i, k) = Io(i, k);
      return SimTK::MassProperties(l.mass, toSimVec(c), SimTK::Inertia(I));
    };
    link_mobod.resize(m.numLinks());
    SimTK::MobilizedBody::Free base(matter.updGround(), SimTK::Transform(), SimTK::Body::Rigid(massProps(m.links()[0])),
                                    SimTK::Transform());
    link_mobod[0] = base.getMobilizedBodyIndex();
    std::vector<SimTK::MobilizedBody::Pin> pins;
    for (const auto& j : m.joints()) {
      const Eigen::Isometry3d X_PJ = zero.linkPose(j.parent_link).inverse() * zero.linkPose(j.child_link);
      Eigen::Isometry3d A = Eigen::Isometry3d::Identity();  // a Pin turns about z: align z with the axis
      A.linear() = Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), j.axis).toRotationMatrix();
      SimTK::MobilizedBody::Pin pin(matter.updMobilizedBody(link_mobod[j.parent_link]), toSim(X_PJ * A),
                                    SimTK::Body::Rigid(massProps(m.links()[j.child_link])), toSim(A));
      link_mobod[j.child_link] = pin.getMobilizedBodyIndex();
      pins.push_back(pin);
    }
    SimTK::Force::UniformGravity(forces, matter, SimTK::Vec3(0, 0, -9.81));
    SimTK::Force::Custom(forces, new Servo(*this));

    // Contact: one half-space per surface, bounded by SurfaceSphereTracker,
    // each in its own clique so that a sphere sees only the surfaces it is
    // made for; spheres carry their surface's friction
    // (Simbody combines two coefficients as 2 m1 m2 / (m1 + m2), equal to
    // the surface's only when both sides have it).
    contact.setTransitionVelocity(opt.transition_velocity);
    const auto& surfaces = scene->surfaces();
    std::vector<SimTK::ContactCliqueId> clique(surfaces.size());
    std::vector<SurfaceSphereTracker::Face> faces;
    auto material = [&](double mu) { return SimTK::ContactMaterial(opt.stiffness, opt.dissipation, mu, mu, 0); };
    for (std::size_t s = 0; s < surfaces.size(); ++s) {
      clique[s] = SimTK::ContactSurface::createNewContactClique();
      // HalfSpace occupies x > 0 of its frame: turn -x onto the surface's outward z.
      const Eigen::Matrix3d R = surfaces[s].frame.linear() * Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitY()).toRotationMatrix();
      SimTK::ContactSurface cs(SimTK::ContactGeometry::HalfSpace(), material(surfaces[s].friction));
      cs.joinClique(clique[s]);
      const SimTK::Transform X_GH(toSimRot(R), toSimVec(surfaces[s].frame.translation()));
      matter.updGround().updBody().addContactSurface(X_GH, cs);
      faces.push_back({X_GH, surfaces[s].frame.inverse(), surfaces[s].polygon});
    }
    tracker.adoptContactTracker(new SurfaceSphereTracker(faces, kSlab, opt.sphere_radius));
    const SimTK::ContactCliqueId robot_clique = SimTK::ContactSurface::createNewContactClique();
    // A sphere on a link that meets surface sf alone.
    auto addSphere = [&](int link, const Eigen::Vector3d& centre, double radius, int sf, const Sphere& tag) {
      SimTK::ContactSurface cs(SimTK::ContactGeometry::Sphere(radius), material(surfaces.at(sf).friction));
      cs.joinClique(robot_clique);
      for (std::size_t s = 0; s < surfaces.size(); ++s)
        if (static_cast<int>(s) != sf) cs.joinClique(clique[s]);
      SimTK::Body& body = matter.updMobilizedBody(link_mobod[link]).updBody();
      const int on_body = body.addContactSurface(SimTK::Transform(toSimVec(centre)), cs);
      sphere_bodies.push_back({static_cast<int>(sphere_bodies.size()), {link_mobod[link], on_body}});
      spheres.push_back(tag);
    };
    for (const auto& [sp, sf] : spotSurfaces(*scene, m, pairs)) {
      const ContactSpot& spot = m.spots()[sp];
      // The spheres' bottoms on the spot's plane (spot z points into the body).
      for (const auto& v : spot.polygon.vertices())
        addSphere(spot.link, spot.frame * Eigen::Vector3d(v.x(), v.y(), opt.sphere_radius), opt.sphere_radius, sf,
                  {sp, sf});
    }
    // The body's shapes on the surfaces they come near (bodyContactPairs).
    for (int b = 0; b < body_pairs; ++b) {
      const auto [link, sf] = bodies[b];
      for (const CollisionShape& sh : m.links().at(link).shapes)
        for (const auto& [centre, radius] : shapeSpheres(sh, opt.sphere_radius)) addSphere(link, centre, radius, sf, {-1, sf, b});
    }
    system.realizeTopology();
    for (const auto& [k, mb] : sphere_bodies)
      sphere_of_surface[static_cast<int>(tracker.getContactSurfaceIndex(mb.first, mb.second))] = spheres[k];

    state = system.getDefaultState();
    q_index.resize(n);
    u_index.resize(n);
    for (const auto& j : m.joints()) {
      q_index[j.index] = pins[j.index].getFirstQIndex(state);
      u_index[j.index] = pins[j.index].getFirstUIndex(state);
    }
    setConfiguration(start);
    // Gains (see DynamicsOptions): from the effort limits and the mass matrix here.
    effort = m.effortLimits();
    kp = effort / opt.full_torque_error;
    system.realize(state, SimTK::Stage::Position);
    SimTK::Matrix M;
    matter.calcM(state, M);
    kd.resize(n);
    for (int j = 0; j < n; ++j) kd[j] = 2 * opt.damping_ratio * std::sqrt(kp[j] * M(u_index[j], u_index[j]));
    ref.q0 = ref.q1 = start.joints;
    ref.dq0 = ref.dq1 = Eigen::VectorXd::Zero(n);

    // Variable step with error control: the step is set by the stiffest
    // force in play (the friction's stiction regularization on a loaded
    // foot, the servos of the light wrist and gripper links), larger when
    // little touches. No interpolation past a report time, so that each
    // reference segment is integrated with the reference it was set for.
    if (opt.integrator == "rk-merson") integ = std::make_unique<SimTK::RungeKuttaMersonIntegrator>(system);
    else if (opt.integrator == "rk3") integ = std::make_unique<SimTK::RungeKutta3Integrator>(system);
    else if (opt.integrator == "cpodes") integ = std::make_unique<SimTK::CPodesIntegrator>(system, SimTK::CPodes::BDF);
    else integ = std::make_unique<SimTK::SemiExplicitEuler2Integrator>(system);
    integ->setAccuracy(opt.accuracy);
    integ->setMaximumStepSize(opt.max_step);
    integ->setAllowInterpolation(false);
    integ->initialize(state);
  }

  std::vector<Sphere> spheres;

  void setConfiguration(const Configuration& q) {
    const auto& base = matter.getMobilizedBody(link_mobod[0]);
    base.setQToFitTransform(state, toSim(q.basePose()));
    base.setUToFitVelocity(state, SimTK::SpatialVec(SimTK::Vec3(0), SimTK::Vec3(0)));
    for (int j = 0; j < robot->numJoints(); ++j) {
      state.updQ()[q_index[j]] = q.joints[j];
      state.updU()[u_index[j]] = 0;
    }
  }

  const SimTK::State& current() const { return integ->getState(); }

  Configuration configuration() const {
    const SimTK::State& st = current();
    system.realize(st, SimTK::Stage::Position);
    Configuration q;
    const Eigen::Isometry3d T = toEigen(matter.getMobilizedBody(link_mobod[0]).getBodyTransform(st));
    q.base_position = T.translation();
    q.base_orientation = Eigen::Quaterniond(T.linear()).normalized();
    q.joints.resize(robot->numJoints());
    for (int j = 0; j < robot->numJoints(); ++j) q.joints[j] = st.getQ()[q_index[j]];
    return q;
  }

  Eigen::Isometry3d spotPose(int spot) const {
    const ContactSpot& s = robot->spots()[spot];
    return toEigen(matter.getMobilizedBody(link_mobod[s.link]).getBodyTransform(current())) * s.frame;
  }

  // Calls f(sphere, force on the robot, its moment about the contact point,
  // the contact point; world) for each active contact on a robot sphere.
  template <class F>
  void forEachSphereForce(F&& f) const {
    const SimTK::State& st = current();
    system.realize(st, SimTK::Stage::Dynamics);
    const SimTK::ContactSnapshot& snap = tracker.getActiveContacts(st);
    for (int i = 0; i < contact.getNumContactForces(st); ++i) {
      const SimTK::ContactForce& cf = contact.getContactForce(st, i);
      if (!snap.hasContact(cf.getContactId())) continue;
      const SimTK::Contact& c = snap.getContactById(cf.getContactId());
      double sign = 1;
      auto it = sphere_of_surface.find(static_cast<int>(c.getSurface2()));
      if (it == sphere_of_surface.end()) {
        it = sphere_of_surface.find(static_cast<int>(c.getSurface1()));
        sign = -1;
      }
      if (it == sphere_of_surface.end()) continue;
      f(it->second, sign * toEigen(cf.getForceOnSurface2()[1]), sign * toEigen(cf.getForceOnSurface2()[0]),
        toEigen(cf.getContactPoint()));
    }
  }

  // Per spot: the contact force and its moment about the spot's origin (world).
  std::vector<SpotWrench> spotWrenches() const {
    system.realize(current(), SimTK::Stage::Position);  // the spots' frames
    std::vector<SpotWrench> out(robot->spots().size());
    std::vector<Eigen::Vector3d> origin(robot->spots().size());
    for (std::size_t s = 0; s < origin.size(); ++s) {
      out[s].frame = spotPose(static_cast<int>(s));
      origin[s] = out[s].frame->translation();
    }
    forEachSphereForce([&](const Sphere& sp, const Eigen::Vector3d& force, const Eigen::Vector3d& moment,
                           const Eigen::Vector3d& at) {
      if (sp.spot < 0) return;
      out[sp.spot].force += force;
      out[sp.spot].moment += moment + (at - origin[sp.spot]).cross(force);
    });
    return out;
  }

  // Per body pair: the contact force on its shapes (world).
  std::vector<Eigen::Vector3d> bodyForces() const {
    std::vector<Eigen::Vector3d> out(body_pairs, Eigen::Vector3d::Zero());
    forEachSphereForce([&](const Sphere& sp, const Eigen::Vector3d& force, const Eigen::Vector3d&, const Eigen::Vector3d&) {
      if (sp.body >= 0) out[sp.body] += force;
    });
    return out;
  }

  std::vector<Eigen::Vector3d> spotForces() const {
    std::vector<Eigen::Vector3d> out;
    for (const SpotWrench& w : spotWrenches()) out.push_back(w.force);
    return out;
  }

  void advanceTo(double t) {
    while (integ->getTime() < t - 1e-12) {
      const auto status = integ->stepTo(t);
      if (status == SimTK::Integrator::EndOfSimulation)
        throw std::runtime_error("the integrator ended the simulation at t = " + std::to_string(integ->getTime()) +
                                 " s: " + integ->getTerminationReasonString(integ->getTerminationReason()));
    }
  }
};

DynamicsSimulator::DynamicsSimulator(const Scenario& sc, const Configuration& start, const DynamicsOptions& options,
                                     const std::vector<std::pair<int, int>>& pairs,
                                     const std::vector<std::pair<int, int>>& body_pairs)
    : impl_(std::make_unique<Impl>(sc, start, options, pairs, body_pairs)) {}
DynamicsSimulator::~DynamicsSimulator() = default;

void DynamicsSimulator::setReference(const Eigen::VectorXd& q, const Eigen::VectorXd& dq, double ramp) {
  Impl& s = *impl_;
  const double t = s.integ->getTime();
  Eigen::VectorXd q_now, dq_now;
  s.ref.at(t, q_now, dq_now);
  s.ref = {t, t + std::max(ramp, 0.0), q_now, dq_now, q, dq};
  if (ramp <= 0) s.integ->reinitialize(SimTK::Stage::Velocity, false);
}
void DynamicsSimulator::advanceTo(double t) { impl_->advanceTo(t); }
double DynamicsSimulator::time() const { return impl_->integ->getTime(); }
Configuration DynamicsSimulator::configuration() const { return impl_->configuration(); }
Eigen::VectorXd DynamicsSimulator::jointVelocities() const {
  Eigen::VectorXd dq(impl_->robot->numJoints());
  for (int j = 0; j < dq.size(); ++j) dq[j] = impl_->current().getU()[impl_->u_index[j]];
  return dq;
}
Eigen::Vector3d DynamicsSimulator::centerOfMass() const {
  const SimTK::State& st = impl_->current();
  impl_->system.realize(st, SimTK::Stage::Position);
  return toEigen(impl_->matter.calcSystemMassCenterLocationInGround(st));
}
std::vector<Eigen::Vector3d> DynamicsSimulator::spotForces() const { return impl_->spotForces(); }
std::vector<SpotWrench> DynamicsSimulator::spotWrenches() const { return impl_->spotWrenches(); }
std::vector<Eigen::Vector3d> DynamicsSimulator::bodyForces() const { return impl_->bodyForces(); }
long DynamicsSimulator::steps() const { return impl_->integ->getNumStepsTaken(); }

// ---------------------------------------------------------------------------

SimulationReport simulate(const Scenario& sc, const Trajectory& tr, const DynamicsOptions& options,
                          const SimulationProgress& progress, const SimulationTrace& trace) {
  if (tr.samples.empty() || tr.phases.empty()) throw std::invalid_argument("the trajectory has no samples or no phases");
  const auto wall0 = std::chrono::steady_clock::now();
  const RobotModel& m = *sc.robot;
  const std::vector<std::pair<int, int>> body_pairs =
      options.body_contacts ? bodyContactPairs(sc, tr, options) : std::vector<std::pair<int, int>>{};
  DynamicsSimulator sim(sc, tr.samples.front().q, options, contactPairs(tr), body_pairs);
  DynamicsSimulator::Impl& S = sim.impl();
  SimulationReport rep;
  rep.options = options;
  const auto& surfaces = sc.scene->surfaces();
  Kinematics kin(sc.robot);
  QuasiStaticChecker lp(sc.robot, sc.scene);

  struct Tracked {
    Eigen::Vector3d start;   // spot origin at the phase's start, world
  };
  std::vector<Tracked> tracked;
  int phase = -1;
  double slip_time = -1;
  std::string slip_reason;

  auto startPhase = [&](int p, double t) {
    phase = p;
    PhaseOutcome po;
    po.phase = p;
    po.t_start = t;
    po.t_end = tr.phases[p].t_end;
    tracked.clear();
    for (const auto& c : tr.phases[p].contacts) {
      ContactOutcome co;
      co.spot = m.spots()[c.spot].name;
      co.surface = surfaces[c.surface].name;
      co.supporting = c.supporting;
      po.contacts.push_back(co);
      tracked.push_back({S.spotPose(c.spot).translation()});
    }
    // The plan's forces, at the phase's middle sample.
    rep.phases.push_back(po);
  };

  const int N = static_cast<int>(tr.samples.size());
  const double dt = tr.dt;
  const int settle_steps = static_cast<int>(std::ceil(options.settle / dt));
  const double total = tr.duration() + settle_steps * dt;
  std::vector<int> middle(tr.phases.size(), -1);
  {
    std::vector<int> first(tr.phases.size(), -1), last(tr.phases.size(), -1);
    for (int k = 0; k < N; ++k) {
      const int p = tr.samples[k].phase;
      if (first[p] < 0) first[p] = k;
      last[p] = k;
    }
    for (std::size_t p = 0; p < tr.phases.size(); ++p)
      if (first[p] >= 0) middle[p] = (first[p] + last[p]) / 2;
  }

  // HRP-2's stabilizer where the bridge runs it; its offsets are added to
  // the references (from the state measured at each period's start).
  std::unique_ptr<FeetStabilizer> stabilizer;
  std::vector<bool> stabilizer_on;
  if (options.stabilizer) {
    stabilizer = std::make_unique<FeetStabilizer>(sc.robot, sc.scene, options.stabilizer_options);
    stabilizer_on = scheduleStabilizer(tr, m, *sc.scene, BridgeConfig{}).sample_on;
  }
  Eigen::VectorXd offset_from = Eigen::VectorXd::Zero(m.numJoints()), offset_to = offset_from;
  // Measured once per period, after it is integrated: the contact wrenches
  // and CoM the report reads are those the next period's stabilizer update takes.
  std::vector<SpotWrench> wrenches = S.spotWrenches();
  Eigen::Vector3d com = sim.centerOfMass();

  std::vector<double> body_first(body_pairs.size(), -1), body_max(body_pairs.size(), 0), body_loaded(body_pairs.size(), 0);
  bool fell = false;
  double last_progress = -1;
  for (int k = 1; k < N + settle_steps && !fell; ++k) {
    const TrajectorySample& from = tr.samples[std::min(k - 1, N - 1)];
    const TrajectorySample& to = tr.samples[std::min(k, N - 1)];
    const double t0 = (k - 1) * dt, t1 = k * dt;
    const Eigen::VectorXd rest = Eigen::VectorXd::Zero(to.dq.size());
    if (stabilizer) {
      const bool on = stabilizer_on[std::min(k, N - 1)];
      offset_from = offset_to;
      offset_to = stabilizer->update(dt, on, to.q, tr.phases[to.phase].contacts, com, wrenches, sim.configuration().basePose());
      if (on && k < N) rep.stabilizer_on_time += dt;
      for (int s = 0; s < static_cast<int>(m.spots().size()); ++s) {
        rep.stabilizer_max_tilt = std::max(rep.stabilizer_max_tilt, stabilizer->tilt(s).norm());
        rep.stabilizer_max_lift = std::max(rep.stabilizer_max_lift, std::abs(stabilizer->lift(s)));
      }
    }
    S.ref = {t0, t1, from.q.joints + offset_from, k - 1 < N ? from.dq : rest, to.q.joints + offset_to,
             k < N ? to.dq : rest};
    if (phase < 0) startPhase(tr.samples[0].phase, 0.0);
    S.advanceTo(t1);
    if (k < N && to.phase != phase) {
      rep.phases.back().t_end = t1;
      startPhase(to.phase, t1);
    }
    PhaseOutcome& po = rep.phases.back();
    const Configuration q = S.configuration();
    // Base against the plan.
    const double drift = (q.base_position - to.q.base_position).norm();
    const double tilt = q.base_orientation.angularDistance(to.q.base_orientation);
    po.base_drift = std::max(po.base_drift, drift);
    po.base_drift_end = drift;
    po.tilt = std::max(po.tilt, tilt);
    for (int j = 0; j < m.numJoints(); ++j) {
      const double e = std::abs(q.joints[j] - to.q.joints[j]);
      if (e > po.tracking) po.tracking = e, po.tracking_joint = m.joints()[j].name;
    }
    // Contacts the plan does not make.
    if (!body_pairs.empty()) {
      const std::vector<Eigen::Vector3d> bf = sim.bodyForces();
      for (std::size_t b = 0; b < bf.size(); ++b) {
        const double fb = bf[b].norm();
        if (fb < 1e-9) continue;
        if (body_first[b] < 0) body_first[b] = t1;
        body_max[b] = std::max(body_max[b], fb);
        body_loaded[b] += dt;
      }
    }
    // Contacts.
    const auto& contacts = tr.phases[phase].contacts;
    const bool at_middle = k == middle[phase];
    wrenches = S.spotWrenches();
    com = sim.centerOfMass();
    std::vector<Eigen::Vector3d> f;
    for (const SpotWrench& w : wrenches) f.push_back(w.force);
    if (at_middle) {
      kin.setConfiguration(to.q);
      const QuasiStaticReport qs = lp.check(kin, contacts);
      for (std::size_t c = 0; c < contacts.size(); ++c) {
        po.contacts[c].force = f[contacts[c].spot];
        po.contacts[c].plan_force_known = qs.feasible;
        if (qs.feasible && c < qs.forces.size())
          for (const auto& fk : qs.forces[c]) po.contacts[c].plan_force += fk;
      }
    }
    for (std::size_t c = 0; c < contacts.size(); ++c) {
      ContactOutcome& co = po.contacts[c];
      const Surface& sf = surfaces[contacts[c].surface];
      const Eigen::Vector3d n = sf.frame.linear().col(2);
      const Eigen::Vector3d p = S.spotPose(contacts[c].spot).translation();
      const Eigen::Vector3d d = p - tracked[c].start;
      co.slip = std::max(co.slip, (d - d.dot(n) * n).norm());
      co.lift = std::max(co.lift, d.dot(n));
      if (f[contacts[c].spot].norm() < 1e-9) co.unloaded_time += dt;
      const Eigen::Vector3d local = sf.frame.inverse() * p;
      if (co.supporting && !sf.polygon.contains(local.head<2>())) co.left_surface = true;
      if (co.supporting && slip_time < 0 && (co.slip > options.slip_bound || co.left_surface)) {
        slip_time = t1;
        char buf[300];
        // A contact that has carried nothing since its phase began did not
        // slip: it never reached its surface (a palm above a table the
        // robot leans away from), which is the thing to say.
        const bool unloaded = co.unloaded_time >= t1 - po.t_start - 0.5 * dt;
        std::snprintf(buf, sizeof buf, "%s on %s %s in phase %d (%.1f mm)", co.spot.c_str(), co.surface.c_str(),
                      unloaded ? "carried no load since the phase began (it never reached its surface) and moved"
                               : co.left_surface ? "left the surface" : "slipped beyond the bound",
                      phase, 1e3 * co.slip);
        slip_reason = buf;
      }
    }
    if (trace) {
      SimulationSample ts;
      ts.t = t1;
      ts.phase = phase;
      ts.stabilizer_on = stabilizer && stabilizer_on[std::min(k, N - 1)];
      ts.com = com;
      kin.setConfiguration(to.q);
      ts.plan_com = kin.centerOfMass();
      ts.base = q.base_position;
      ts.plan_base = to.q.base_position;
      ts.tilt = tilt;
      const Eigen::AngleAxisd err(q.base_orientation * to.q.base_orientation.inverse());
      ts.tilt_vector = err.angle() * err.axis();
      ts.spot_forces = f;
      Eigen::Vector3d F = Eigen::Vector3d::Zero(), M = Eigen::Vector3d::Zero();
      for (int s = 0; s < static_cast<int>(wrenches.size()); ++s) {
        F += wrenches[s].force;
        M += wrenches[s].moment + S.spotPose(s).translation().cross(wrenches[s].force);
      }
      if (F.z() > 1.0) ts.zmp = Eigen::Vector2d(-M.y() / F.z(), M.x() / F.z());
      if (stabilizer && stabilizer_on[std::min(k, N - 1)]) ts.wanted_zmp = stabilizer->wantedZmp();
      for (int s = 0; s < static_cast<int>(m.spots().size()); ++s)
        if (isFootSpot(m, s)) ts.foot_tilts.push_back(stabilizer ? stabilizer->tilt(s) : Eigen::Vector2d::Zero());
      trace(ts);
    }
    // A fall: the base far below the plan or tilted far from it.
    if (to.q.base_position.z() - q.base_position.z() > options.fall_height || tilt > options.fall_tilt) {
      fell = true;
      rep.verdict = SimulationReport::Verdict::Fell;
      rep.verdict_time = t1;
      char buf[200];
      std::snprintf(buf, sizeof buf, "base %.0f mm below the plan, tilted %.1f deg from it, in phase %d",
                    1e3 * (to.q.base_position.z() - q.base_position.z()), tilt * 180 / M_PI, phase);
      rep.reason = buf;
      if (slip_time >= 0) rep.reason += "; before that, at " + std::to_string(slip_time) + " s, " + slip_reason;
    }
    rep.motion_time = t1;
    if (progress && t1 - last_progress >= 0.1) {
      progress(t1, total);
      last_progress = t1;
    }
  }
  if (!rep.phases.empty() && !fell) rep.phases.back().t_end = rep.motion_time;
  if (!fell) {
    if (slip_time >= 0) {
      rep.verdict = SimulationReport::Verdict::Slipped;
      rep.verdict_time = slip_time;
      rep.reason = slip_reason;
    } else {
      rep.verdict_time = rep.motion_time;
    }
  }
  for (auto& p : rep.phases)
    for (auto& c : p.contacts)
      c.never_loaded = c.supporting && p.t_end - p.t_start > dt && c.unloaded_time >= p.t_end - p.t_start - 0.5 * dt;
  for (const auto& p : rep.phases) {
    rep.worst_base_drift = std::max(rep.worst_base_drift, p.base_drift);
    if (p.tracking > rep.worst_tracking) rep.worst_tracking = p.tracking, rep.worst_tracking_joint = p.tracking_joint;
    for (const auto& c : p.contacts)
      if (c.supporting && c.slip > rep.worst_slip)
        rep.worst_slip = c.slip, rep.worst_slip_contact = c.spot + "@" + c.surface + " (phase " + std::to_string(p.phase) + ")";
  }
  for (std::size_t b = 0; b < body_pairs.size(); ++b)
    if (body_first[b] >= 0)
      rep.body_contacts.push_back({m.links()[body_pairs[b].first].name, surfaces[body_pairs[b].second].name,
                                   body_max[b], body_first[b], body_loaded[b]});
  std::stable_sort(rep.body_contacts.begin(), rep.body_contacts.end(),
                   [](const BodyContactOutcome& a, const BodyContactOutcome& b) { return a.first_time < b.first_time; });
  rep.base_within_bound = rep.worst_base_drift <= options.base_bound;
  rep.integrator_steps = sim.steps();
  rep.mean_step = rep.integrator_steps > 0 ? rep.motion_time / rep.integrator_steps : 0;
  rep.wall_time = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  if (progress) progress(rep.motion_time, total);
  return rep;
}

// ---------------------------------------------------------------------------

std::string reportToJson(const SimulationReport& r) {
  using nlohmann::json;
  auto vec = [](const Eigen::Vector3d& v) { return json::array({v.x(), v.y(), v.z()}); };
  json j;
  j["format"] = "acyclic.simulation/1";
  j["verdict"] = toString(r.verdict);
  j["verdict_time"] = r.verdict_time;
  j["reason"] = r.reason;
  j["motion_time"] = r.motion_time;
  j["wall_time"] = r.wall_time;
  j["worst_slip"] = r.worst_slip;
  j["worst_slip_contact"] = r.worst_slip_contact;
  j["worst_base_drift"] = r.worst_base_drift;
  j["base_within_bound"] = r.base_within_bound;
  j["worst_tracking"] = r.worst_tracking;
  j["worst_tracking_joint"] = r.worst_tracking_joint;
  j["integrator"] = {{"name", r.options.integrator}, {"accuracy", r.options.accuracy}, {"max_step", r.options.max_step},
                     {"steps", r.integrator_steps}, {"mean_step", r.mean_step}};
  j["stabilizer"] = {{"on", r.options.stabilizer}, {"on_time", r.stabilizer_on_time},
                     {"max_tilt", r.stabilizer_max_tilt}, {"max_lift", r.stabilizer_max_lift},
                     {"zmp_com_gain", r.options.stabilizer_options.zmp_com_gain},
                     {"zmp_velocity_gain", r.options.stabilizer_options.zmp_velocity_gain},
                     {"cop_gain", r.options.stabilizer_options.cop_gain},
                     {"cop_leak", r.options.stabilizer_options.cop_leak},
                     {"max_tilt_bound", r.options.stabilizer_options.max_tilt},
                     {"force_damping", r.options.stabilizer_options.force_damping},
                     {"force_leak", r.options.stabilizer_options.force_leak},
                     {"max_lift_bound", r.options.stabilizer_options.max_lift},
                     {"off_time", r.options.stabilizer_options.off_time}};
  j["options"] = {{"full_torque_error", r.options.full_torque_error}, {"damping_ratio", r.options.damping_ratio},
                  {"sphere_radius", r.options.sphere_radius}, {"stiffness", r.options.stiffness},
                  {"dissipation", r.options.dissipation}, {"transition_velocity", r.options.transition_velocity},
                  {"settle", r.options.settle}, {"slip_bound", r.options.slip_bound},
                  {"body_contacts", r.options.body_contacts}, {"body_contact_range", r.options.body_contact_range},
                  {"fall_height", r.options.fall_height}, {"fall_tilt", r.options.fall_tilt},
                  {"base_bound", r.options.base_bound}};
  json bodies = json::array();
  for (const auto& b : r.body_contacts)
    bodies.push_back({{"link", b.link}, {"surface", b.surface}, {"max_force", b.max_force},
                      {"first_time", b.first_time}, {"loaded_time", b.loaded_time}});
  j["body_contacts"] = bodies;
  json phases = json::array();
  for (const auto& p : r.phases) {
    json jp = {{"phase", p.phase}, {"t_start", p.t_start}, {"t_end", p.t_end}, {"base_drift", p.base_drift},
               {"base_drift_end", p.base_drift_end}, {"tilt", p.tilt}, {"tracking", p.tracking},
               {"tracking_joint", p.tracking_joint}};
    json cs = json::array();
    for (const auto& c : p.contacts) {
      json jc = {{"spot", c.spot}, {"surface", c.surface}, {"supporting", c.supporting}, {"slip", c.slip},
                 {"lift", c.lift}, {"unloaded_time", c.unloaded_time}, {"never_loaded", c.never_loaded}, {"left_surface", c.left_surface},
                 {"force", vec(c.force)}};
      jc["plan_force"] = c.plan_force_known ? vec(c.plan_force) : json(nullptr);
      cs.push_back(jc);
    }
    jp["contacts"] = cs;
    phases.push_back(jp);
  }
  j["phases"] = phases;
  return j.dump(2);
}

void writeReport(const SimulationReport& r, const std::string& path) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp);
    if (!out) throw std::runtime_error("cannot write " + tmp);
    out << reportToJson(r) << "\n";
    if (!out) throw std::runtime_error("cannot write " + tmp);
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) throw std::runtime_error("cannot rename " + tmp + " to " + path);
}

}  // namespace acyclic::hrp2
