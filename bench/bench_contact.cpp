// bench-contact: minimum signed distance between random convex pairs
// (uniform random orientations), three sets:
//   ellipsoids with semi-axes 0.5-1.5 and with aspect up to 10 (0.15-1.5), 2,000 pairs per class;
//   superellipsoids (thesis form, exponents 2-4, semi-axes 0.5-1.5), 400 pairs per class;
// classes:
//   separated: reference distance > 0 (placed with a gap of 0.01-1 mm along a random direction),
//   shallow:   penetration depth 0-0.05 mm (reference in [-0.05, 0)),
//   deep:      penetration depth > 0.05 mm (placed with an overlap of 0.1-1 mm along a random direction).
// Pairs are drawn and kept when the reference lands in the class.
// Reference: the long-double support-function dual (contact/reference.hpp).
// Each benchmark iteration is one query, cycling through the class's pairs.
// Counters: median_ns (median over pairs of the fastest of 3 timed calls),
// max_err / p99_err (mm, against the reference), failures (error > 1e-3 or
// no answer), answered (pairs the method gave a distance for).
// Peers: Simbody's ContactTracker::ConvexImplicitPair (the same six equations,
// reports overlap only; ellipsoids), libccd GJK+EPA and MPR (penetration only;
// our exact support function), FCL's fcl::distance with signed distance
// (its Ellipsoid shape, libccd GJK/EPA inside, tolerance 1e-6: Debian's build
// asserts at tighter ones) and Bullet's btGjkEpaSolver2::SignedDistance in
// double precision (our exact support function, margin 0).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <random>
#include <vector>

#include <Eigen/Geometry>
#include <BulletCollision/CollisionShapes/btConvexInternalShape.h>
#include <BulletCollision/NarrowPhaseCollision/btGjkEpa2.h>
#include <Simbody.h>
#include <benchmark/benchmark.h>
#include <ccd/ccd.h>
#include <fcl/geometry/shape/ellipsoid.h>
#include <fcl/narrowphase/distance.h>

#include "articula/contact/common_normal.hpp"
#include "articula/contact/plane_contact.hpp"
#include "articula/testsupport/contact_reference.hpp"

namespace {

using namespace articula::contact;
using Eigen::Vector3d;

constexpr int kPairs = 2000;       // per class, ellipsoids
constexpr int kSuperPairs = 400;   // per class, superellipsoids (the reference is slower)
const char* kClassNames[3] = {"separated", "shallow", "deep"};
const char* kSetNames[3] = {", axes 0.5-1.5", ", aspect<=10", ", superellipsoids g 2-4"};

struct Pair {
  ConvexShape a, b;
  double reference;
  ContactResult previous;  // solution one small motion step earlier (warm start)
};

// set: 0 ellipsoids, axes 0.5-1.5; 1 ellipsoids, aspect <= 10; 2 superellipsoids, exponents 2-4.
std::vector<Pair> makePairs(int cls, int set) {
  std::mt19937_64 rng(1000 + 10 * cls + set);
  std::normal_distribution<double> g;
  std::uniform_real_distribution<double> radius(set == 1 ? 0.15 : 0.5, 1.5), exponent(2.0, 4.0);
  const double lo[3] = {0.01, set == 2 ? -0.05 : -0.1, -1.0}, hi[3] = {1.0, 0.0, -0.1};
  std::uniform_real_distribution<double> gap(lo[cls], hi[cls]);
  auto shape = [&] {
    const Eigen::Matrix3d R = Eigen::Quaterniond(g(rng), g(rng), g(rng), g(rng)).normalized().toRotationMatrix();
    const Vector3d radii(radius(rng), radius(rng), radius(rng));
    if (set < 2) return makeConvexShape(Vector3d::Zero(), R, radii);
    return makeConvexShape(Vector3d::Zero(), R, radii, Vector3d(exponent(rng), exponent(rng), exponent(rng)));
  };
  std::vector<Pair> pairs;
  while (static_cast<int>(pairs.size()) < (set == 2 ? kSuperPairs : kPairs)) {
    Pair p{shape(), shape(), 0.0, {}};
    const Vector3d dir = Vector3d(g(rng), g(rng), g(rng)).normalized();
    const double ea = dir.dot(toGlobal(p.a, supportCanonical(p.a, dir)));
    const double eb = -dir.dot(toGlobal(p.b, supportCanonical(p.b, -dir)));
    p.b.center = dir * (ea + eb + gap(rng));
    p.reference = referenceConvexDistance(p.a, p.b, 1500, 4);
    const bool in_class = cls == 0 ? p.reference > 0.0 : cls == 1 ? p.reference >= -0.05 && p.reference < 0.0
                                                                  : p.reference < -0.05;
    if (!in_class) continue;
    // One step earlier: b 0.01 mm and 0.01 rad away.
    ConvexShape before = p.b;
    before.center += 0.01 * Vector3d(g(rng), g(rng), g(rng)).normalized();
    before.rotation = Eigen::AngleAxisd(0.01, Vector3d(g(rng), g(rng), g(rng)).normalized()) * before.rotation;
    p.previous = computeContact(p.a, before);
    pairs.push_back(p);
  }
  return pairs;
}

const std::vector<Pair>& pairSet(int cls, int set) {
  static std::vector<Pair> sets[3][3];
  if (sets[cls][set].empty()) sets[cls][set] = makePairs(cls, set);
  return sets[cls][set];
}

// A method answers a pair with a signed distance, or NaN for "no answer".
using Method = std::function<double(const Pair&)>;

void accuracyCounters(benchmark::State& state, const std::vector<Pair>& pairs, const Method& method) {
  std::vector<double> errors, times;
  int failures = 0, answered = 0;
  for (const Pair& p : pairs) {
    double d = NAN, best = INFINITY;
    for (int r = 0; r < 3; ++r) {
      const auto t0 = std::chrono::steady_clock::now();
      d = method(p);
      best = std::min(best, std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - t0).count());
    }
    times.push_back(best);
    if (!std::isfinite(d)) {
      ++failures;
      continue;
    }
    ++answered;
    const double e = std::fabs(d - p.reference);
    errors.push_back(e);
    failures += e > 1e-3;
  }
  std::sort(times.begin(), times.end());
  std::sort(errors.begin(), errors.end());
  state.counters["median_ns"] = times[times.size() / 2];
  state.counters["max_err"] = errors.empty() ? NAN : errors.back();
  state.counters["p99_err"] = errors.empty() ? NAN : errors[errors.size() * 99 / 100];
  state.counters["failures"] = failures;
  state.counters["answered"] = answered;
}

void runMethod(benchmark::State& state, const Method& method) {
  const auto& pairs = pairSet(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
  state.SetLabel(std::string(kClassNames[state.range(0)]) + kSetNames[state.range(1)]);
  size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(method(pairs[i]));
    if (++i == pairs.size()) i = 0;
  }
  accuracyCounters(state, pairs, method);
}

// ---------------------------------------------------------------- ours
// Also counts the mean Newton iterations and starts per query (where the time goes).
void runOurs(benchmark::State& state, bool warm) {
  runMethod(state, [warm](const Pair& p) { return computeContact(p.a, p.b, {}, warm ? &p.previous : nullptr).distance; });
  double iterations = 0.0, starts = 0.0;
  const auto& pairs = pairSet(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
  for (const Pair& p : pairs) {
    const ContactSummary s = computeContact(p.a, p.b, {}, warm ? &p.previous : nullptr).summary;
    iterations += s.iterations;
    starts += s.starts;
  }
  state.counters["mean_iterations"] = iterations / static_cast<double>(pairs.size());
  state.counters["mean_starts"] = starts / static_cast<double>(pairs.size());
}
void BM_OursCold(benchmark::State& state) { runOurs(state, false); }
void BM_OursWarm(benchmark::State& state) { runOurs(state, true); }

// ---------------------------------------------------------------- Simbody
SimTK::Transform simbodyTransform(const ConvexShape& s) {
  SimTK::Mat33 R;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) R(r, c) = s.rotation(r, c);
  return SimTK::Transform(SimTK::Rotation(R, true), SimTK::Vec3(s.center[0], s.center[1], s.center[2]));
}
void BM_Simbody(benchmark::State& state) {
  const SimTK::ContactTracker::ConvexImplicitPair tracker(SimTK::ContactGeometry::Ellipsoid::classTypeId(),
                                                          SimTK::ContactGeometry::Ellipsoid::classTypeId());
  runMethod(state, [&](const Pair& p) -> double {
    const SimTK::ContactGeometry::Ellipsoid ea(SimTK::Vec3(p.a.radii[0], p.a.radii[1], p.a.radii[2]));
    const SimTK::ContactGeometry::Ellipsoid eb(SimTK::Vec3(p.b.radii[0], p.b.radii[1], p.b.radii[2]));
    SimTK::Contact current;
    const SimTK::UntrackedContact prior{SimTK::ContactSurfaceIndex(0), SimTK::ContactSurfaceIndex(1)};
    if (!tracker.trackContact(prior, simbodyTransform(p.a), ea, simbodyTransform(p.b), eb, SimTK::Infinity, current))
      return NAN;
    if (current.isEmpty()) return NAN;  // separated: no contact reported
    if (SimTK::PointContact::isInstance(current))
      return -static_cast<const SimTK::PointContact&>(current).getDepth();
    if (SimTK::CircularPointContact::isInstance(current))
      return -SimTK::CircularPointContact::getAs(current).getDepth();
    if (SimTK::EllipticalPointContact::isInstance(current))
      return -SimTK::EllipticalPointContact::getAs(current).getDepth();
    return NAN;  // separated: Simbody reports no contact (and no distance)
  });
}

// ---------------------------------------------------------------- libccd
void shapeSupport(const void* obj, const ccd_vec3_t* dir, ccd_vec3_t* out) {
  const ConvexShape& s = *static_cast<const ConvexShape*>(obj);
  const Vector3d v(dir->v[0], dir->v[1], dir->v[2]);
  const Vector3d x = toGlobal(s, supportCanonical(s, v));
  ccdVec3Set(out, x[0], x[1], x[2]);
}
void shapeCenter(const void* obj, ccd_vec3_t* out) {
  const ConvexShape& s = *static_cast<const ConvexShape*>(obj);
  ccdVec3Set(out, s.center[0], s.center[1], s.center[2]);
}
ccd_t ccdSetup() {
  ccd_t ccd;
  CCD_INIT(&ccd);
  ccd.support1 = shapeSupport;
  ccd.support2 = shapeSupport;
  ccd.center1 = shapeCenter;
  ccd.center2 = shapeCenter;
  ccd.max_iterations = 1000;
  return ccd;
}
using CcdPenetration = int (*)(const void*, const void*, const ccd_t*, ccd_real_t*, ccd_vec3_t*, ccd_vec3_t*);
template <CcdPenetration Penetration>
void BM_Libccd(benchmark::State& state) {
  const ccd_t ccd = ccdSetup();
  runMethod(state, [&](const Pair& p) -> double {
    ccd_real_t depth;
    ccd_vec3_t dir, pos;
    return Penetration(&p.a, &p.b, &ccd, &depth, &dir, &pos) == 0 ? -static_cast<double>(depth) : NAN;
  });
}
void BM_LibccdGjkEpa(benchmark::State& state) { BM_Libccd<ccdGJKPenetration>(state); }
void BM_LibccdMpr(benchmark::State& state) { BM_Libccd<ccdMPRPenetration>(state); }

// ---------------------------------------------------------------- FCL
void BM_Fcl(benchmark::State& state) {
  fcl::DistanceRequestd request;
  request.enable_signed_distance = true;
  request.enable_nearest_points = true;
  request.distance_tolerance = 1e-6;  // Debian's FCL asserts at tighter tolerances
  request.gjk_solver_type = fcl::GST_LIBCCD;
  auto transform = [](const ConvexShape& s) {
    fcl::Transform3d t = fcl::Transform3d::Identity();
    t.linear() = s.rotation;
    t.translation() = s.center;
    return t;
  };
  runMethod(state, [&](const Pair& p) -> double {
    const fcl::Ellipsoidd ea(p.a.radii), eb(p.b.radii);
    fcl::DistanceResultd result;
    fcl::distance(&ea, transform(p.a), &eb, transform(p.b), request, result);
    return result.min_distance;
  });
}

// ---------------------------------------------------------------- Bullet (double precision)
// An (super)ellipsoid with our exact support mapping (local axes), margin 0.
class BulletShape : public btConvexInternalShape {
 public:
  explicit BulletShape(const ConvexShape& s) : local_(s) {
    local_.center.setZero();
    local_.rotation.setIdentity();
    setMargin(0.0);
  }
  btVector3 localGetSupportingVertexWithoutMargin(const btVector3& v) const override {
    const Vector3d w(v.x(), v.y(), v.z());
    if (!(w.norm() > 0.0)) return btVector3(local_.radii[0], 0.0, 0.0);
    const Vector3d x = toGlobal(local_, supportCanonical(local_, w));
    return btVector3(x[0], x[1], x[2]);
  }
  btVector3 localGetSupportingVertex(const btVector3& v) const override {
    return localGetSupportingVertexWithoutMargin(v);
  }
  void batchedUnitVectorGetSupportingVertexWithoutMargin(const btVector3* v, btVector3* out, int n) const override {
    for (int i = 0; i < n; ++i) out[i] = localGetSupportingVertexWithoutMargin(v[i]);
  }
  void getAabb(const btTransform& t, btVector3& lo, btVector3& hi) const override { getAabbSlow(t, lo, hi); }
  void calculateLocalInertia(btScalar, btVector3& inertia) const override { inertia.setZero(); }
  const char* getName() const override { return "ArticulaConvexShape"; }

 private:
  ConvexShape local_;
};
void BM_Bullet(benchmark::State& state) {
  auto transform = [](const ConvexShape& s) {
    const Eigen::Matrix3d& R = s.rotation;
    return btTransform(btMatrix3x3(R(0, 0), R(0, 1), R(0, 2), R(1, 0), R(1, 1), R(1, 2), R(2, 0), R(2, 1), R(2, 2)),
                       btVector3(s.center[0], s.center[1], s.center[2]));
  };
  runMethod(state, [&](const Pair& p) -> double {
    const BulletShape ea(p.a), eb(p.b);
    btGjkEpaSolver2::sResults results;
    const Vector3d guess = p.b.center - p.a.center;
    // Distance (GJK) when separated, else Penetration (EPA): distance < 0.
    const bool ok = btGjkEpaSolver2::SignedDistance(&ea, transform(p.a), &eb, transform(p.b),
                                                    btVector3(guess[0], guess[1], guess[2]), results);
    return ok ? static_cast<double>(results.distance) : NAN;
  });
}

// ---------------------------------------------------------------- superellipsoid-plane
// Closed form (support mapping, 1-D root find for unequal exponents 2-4).
// Counters: max |F| at the answer and max (1 - n_shape . (-n_plane)), i.e.
// how exactly the point lies on the surface with the plane's normal.
void BM_SuperellipsoidPlane(benchmark::State& state) {
  std::mt19937_64 rng(77);
  std::normal_distribution<double> g;
  std::uniform_real_distribution<double> radius(0.5, 1.5), exponent(2.0, 4.0);
  struct Query {
    ConvexShape s;
    Vector3d p, n;
  };
  std::vector<Query> queries;
  for (int i = 0; i < kPairs; ++i)
    queries.push_back({makeConvexShape(Vector3d(g(rng), g(rng), g(rng)),
                                       Eigen::Quaterniond(g(rng), g(rng), g(rng), g(rng)).normalized().toRotationMatrix(),
                                       Vector3d(radius(rng), radius(rng), radius(rng)),
                                       Vector3d(exponent(rng), exponent(rng), exponent(rng))),
                       Vector3d(g(rng), g(rng), g(rng)), Vector3d(g(rng), g(rng), g(rng)).normalized()});
  size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(shapePlaneContact(queries[i].s, queries[i].p, queries[i].n).distance);
    if (++i == queries.size()) i = 0;
  }
  double max_f = 0.0, max_angle = 0.0;
  for (const Query& q : queries) {
    const ContactResult r = shapePlaneContact(q.s, q.p, q.n);
    const auto e = evaluateCanonical(q.s, toCanonical(q.s, r.point_a));
    const Vector3d n = (q.s.rotation * e.gradient.cwiseQuotient(q.s.radii)).normalized();
    max_f = std::max(max_f, std::fabs(e.value));
    max_angle = std::max(max_angle, 1.0 - n.dot(-q.n));
  }
  state.counters["max_abs_F"] = max_f;
  state.counters["max_1_minus_cos"] = max_angle;
}
BENCHMARK(BM_SuperellipsoidPlane);

// Args {class, set}; Simbody and FCL take ellipsoids only.
void ellipsoidClasses(benchmark::internal::Benchmark* b) {
  for (int set : {0, 1})
    for (int cls : {0, 1, 2}) b->Args({cls, set});
}
void allClasses(benchmark::internal::Benchmark* b) {
  for (int set : {0, 1, 2})
    for (int cls : {0, 1, 2}) b->Args({cls, set});
}
BENCHMARK(BM_OursCold)->Apply(allClasses);
BENCHMARK(BM_OursWarm)->Apply(allClasses);
BENCHMARK(BM_Simbody)->Apply(ellipsoidClasses);
BENCHMARK(BM_LibccdGjkEpa)->Apply(allClasses);
BENCHMARK(BM_LibccdMpr)->Apply(allClasses);
BENCHMARK(BM_Fcl)->Apply(ellipsoidClasses);
BENCHMARK(BM_Bullet)->Apply(allClasses);

}  // namespace

BENCHMARK_MAIN();
