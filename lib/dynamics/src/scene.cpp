#include "articula/dynamics/scene.hpp"

#include <cmath>
#include <fstream>
#include <initializer_list>
#include <optional>
#include <string_view>

#include "articula/core/json_file.hpp"
#include "articula/core/error.hpp"
#include "articula/core/excerpt.hpp"
#include "articula/fit/fits_json.hpp"
#include "articula/geometry/pose.hpp"

namespace articula::dynamics {
namespace {

using nlohmann::json;
constexpr double kDegree = M_PI / 180.0;

[[noreturn]] void refuse(const std::string& where, const std::string& field, const std::string& expected,
                         const json& found) {
  throw InputError(where + ": " + field + ": expected " + expected + ", found " + describeJson(found));
}

const json* member(const json& object, const char* key) {
  const auto it = object.find(key);
  return it == object.end() ? nullptr : &*it;
}

double number(const json& object, const char* key, const std::string& where, std::optional<double> fallback,
              double lo, double hi, const std::string& range) {
  const json* v = member(object, key);
  if (!v) {
    if (fallback) return *fallback;
    throw InputError(where + ": missing \"" + key + "\" (" + range + ")");
  }
  if (!v->is_number() || !(v->get<double>() >= lo && v->get<double>() <= hi)) refuse(where, key, range, *v);
  return v->get<double>();
}

Eigen::Vector3d vector3(const json& object, const char* key, const std::string& where,
                        std::optional<Eigen::Vector3d> fallback, double limit = 1e6) {
  const json* v = member(object, key);
  if (!v) {
    if (fallback) return *fallback;
    throw InputError(where + ": missing \"" + key + "\" (three numbers)");
  }
  if (!v->is_array() || v->size() != 3) refuse(where, key, "three numbers", *v);
  Eigen::Vector3d out;
  for (int i = 0; i < 3; ++i) {
    const json& x = (*v)[static_cast<size_t>(i)];
    if (!x.is_number() || !(std::fabs(x.get<double>()) <= limit))
      refuse(where, key, "three numbers within +-" + excerpt(std::to_string(limit)), *v);
    out[i] = x.get<double>();
  }
  return out;
}

std::string text(const json& object, const char* key, const std::string& where, std::optional<std::string> fallback) {
  const json* v = member(object, key);
  if (!v) {
    if (fallback) return *fallback;
    throw InputError(where + ": missing \"" + key + "\"");
  }
  if (!v->is_string()) refuse(where, key, "a string", *v);
  return v->get<std::string>();
}

const json& object(const json& parent, const char* key, const std::string& where) {
  const json* v = member(parent, key);
  if (!v) throw InputError(where + ": missing \"" + key + "\" (an object)");
  if (!v->is_object()) refuse(where, key, "an object", *v);
  return *v;
}

/// Refuses a key of `object` that is none of `known`: a misspelt key
/// ("disipation") would otherwise leave its default in force unseen.
void onlyKeys(const json& object, const std::string& where, std::initializer_list<std::string_view> known) {
  for (const auto& [key, value] : object.items()) {
    bool listed = false;
    for (std::string_view k : known) listed = listed || key == k;
    if (listed) continue;
    std::string expected;
    for (std::string_view k : known) expected += (expected.empty() ? "" : ", ") + std::string(k);
    throw InputError(where + ": unknown key \"" + excerpt(key) + "\" (expected " + expected + ")");
  }
}

int bodyIndex(const std::string& name, const std::vector<SceneBody>& bodies) {
  for (size_t i = 0; i < bodies.size(); ++i)
    if (bodies[i].name == name) return static_cast<int>(i);
  return -1;
}

SceneJoint readJoint(const json& j, const std::string& where, const std::vector<SceneBody>& earlier) {
  if (!j.is_object()) refuse(where, "joint", "an object", j);
  SceneJoint joint;
  onlyKeys(j, where, {"type", "parent", "point_in_parent", "point_in_child", "axis", "stiffness", "damping",
                      "rest_angle_deg", "angle_deg", "rate_deg_s"});
  if (text(j, "type", where, "revolute") != "revolute") refuse(where, "type", "revolute", j.at("type"));
  const std::string parent = text(j, "parent", where, std::nullopt);
  joint.parent = bodyIndex(parent, earlier);
  if (joint.parent < 0)
    throw InputError(where + ": parent \"" + excerpt(parent) + "\" is not a body listed before this one");
  joint.point_in_parent = vector3(j, "point_in_parent", where, std::nullopt, 1e3);
  joint.point_in_child = vector3(j, "point_in_child", where, std::nullopt, 1e3);
  joint.axis = vector3(j, "axis", where, std::nullopt);
  if (!(joint.axis.norm() > 0)) refuse(where, "axis", "a non-zero vector", j.at("axis"));
  joint.axis.normalize();
  joint.stiffness = number(j, "stiffness", where, 0.0, 0, 1e9, "a stiffness >= 0 (N m/rad)");
  joint.damping = number(j, "damping", where, 0.0, 0, 1e9, "a damping >= 0 (N m s/rad)");
  joint.rest_angle_deg = number(j, "rest_angle_deg", where, 0.0, -360, 360, "an angle of -360 to 360 degrees");
  joint.angle_deg = number(j, "angle_deg", where, 0.0, -360, 360, "an angle of -360 to 360 degrees");
  joint.rate_deg_s = number(j, "rate_deg_s", where, 0.0, -1e6, 1e6, "a rate within +-1e6 degrees/s");
  return joint;
}

SceneBody readBody(const json& j, const std::string& where, const std::vector<SceneBody>& earlier) {
  if (!j.is_object()) refuse(where, "body", "an object", j);
  SceneBody b;
  onlyKeys(j, where, {"name", "mass", "inertia", "joint", "position", "angles_deg", "velocity", "angular_velocity"});
  b.name = text(j, "name", where, std::nullopt);
  b.mass = number(j, "mass", where, std::nullopt, 1e-9, 1e9, "a mass in kg, 1e-9 to 1e9");
  b.inertia = vector3(j, "inertia", where, std::nullopt, 1e9);
  const Eigen::Vector3d& I = b.inertia;
  if (!(I.minCoeff() > 0) || I[0] + I[1] < I[2] || I[1] + I[2] < I[0] || I[0] + I[2] < I[1])
    refuse(where, "inertia", "principal moments > 0 that satisfy the triangle inequality", j.at("inertia"));
  if (const json* joint = member(j, "joint")) {
    b.joint = readJoint(*joint, where + " joint", earlier);
    for (const char* key : {"position", "angles_deg", "velocity", "angular_velocity"})
      if (member(j, key))
        throw InputError(where + ": \"" + key + "\" of a hinged body: its pose and velocity follow from its parent "
                         "and the joint's angle_deg and rate_deg_s");
    return b;
  }
  b.position = vector3(j, "position", where, Eigen::Vector3d::Zero());
  b.angles_deg = vector3(j, "angles_deg", where, Eigen::Vector3d::Zero(), 3600);
  b.velocity = vector3(j, "velocity", where, Eigen::Vector3d::Zero(), 1e4);
  b.angular_velocity = vector3(j, "angular_velocity", where, Eigen::Vector3d::Zero(), 1e5);
  return b;
}

ContactLaws readLaws(const json& j, const std::string& where) {
  ContactLaws laws;
  const json& n = object(j, "normal_law", where);
  const std::string w = where + " normal_law";
  const std::string law = text(n, "law", w, "hunt-crossley");
  if (law == "hertz") {
    onlyKeys(n, w + " (hertz)", {"law", "stiffness", "exponent"});
    laws.normal.law = contact::NormalLaw::Hertz;
  } else if (law == "hunt-crossley") {
    onlyKeys(n, w + " (hunt-crossley)", {"law", "stiffness", "exponent", "dissipation"});
    laws.normal.law = contact::NormalLaw::HuntCrossley;
    laws.normal.dissipation = number(n, "dissipation", w, 0.0, 0, 1e6, "a dissipation >= 0 (s/m)");
  } else if (law == "lankarani-nikravesh") {
    onlyKeys(n, w + " (lankarani-nikravesh)", {"law", "stiffness", "exponent", "restitution", "impact_speed"});
    laws.normal.law = contact::NormalLaw::LankaraniNikravesh;
    laws.normal.restitution = number(n, "restitution", w, std::nullopt, 1e-6, 1, "a restitution in (0, 1]");
    laws.normal.impact_speed = number(n, "impact_speed", w, std::nullopt, 1e-9, 1e4, "an impact speed > 0 (m/s)");
  } else {
    refuse(w, "law", "hertz, hunt-crossley or lankarani-nikravesh", n.at("law"));
  }
  laws.normal.stiffness = number(n, "stiffness", w, std::nullopt, 1e-9, 1e15, "a stiffness > 0 (N/m^exponent)");
  laws.normal.exponent = number(n, "exponent", w, 1.5, 1, 3, "an exponent of 1 to 3");
  if (const json* f = member(j, "friction")) {
    const std::string fw = where + " friction";
    if (!f->is_object()) refuse(where, "friction", "an object", *f);
    onlyKeys(*f, fw, {"dynamic", "static", "viscous", "transition_speed"});
    laws.friction.dynamic = number(*f, "dynamic", fw, 0.0, 0, 10, "a coefficient of 0 to 10");
    laws.friction.static_peak = number(*f, "static", fw, laws.friction.dynamic, 0, 10, "a coefficient of 0 to 10");
    laws.friction.viscous = number(*f, "viscous", fw, 0.0, 0, 1e6, "a coefficient >= 0 (s/m)");
    laws.friction.transition_speed = number(*f, "transition_speed", fw, 1e-3, 1e-9, 1e3, "a speed > 0 (m/s)");
  }
  return laws;
}

/// A fitted head from a fits.json as a contact surface: its model's entry,
/// millimetres to metres, its pose in the CT's LPS frame (the body's frame)
/// unless the shape gives `center` or `angles_deg`.
contact::ConvexShape readFittedShape(const json& s, const std::string& sw, const std::string& model,
                                     const std::filesystem::path& folder) {
  std::filesystem::path file = text(s, "fits", sw, std::nullopt);
  if (file.is_relative()) file = folder / file;
  const json document = readJsonFile(file, sw + " fits");
  geometry::ShapeParameters p;
  bool found = false;
  for (const geometry::ShapeParameters& q : fit::shapesFromFitsJson(document, file.string()))
    if (geometry::modelName(q.model) == model) p = q, found = true;
  if (!found) throw InputError(sw + ": " + file.string() + " has no \"" + excerpt(model) + "\" fit");
  constexpr double kMetresPerMm = 1e-3;
  try {
    contact::ConvexShape shape = contact::shapeFromParameters(p);
    shape.radii *= kMetresPerMm;
    shape.center = member(s, "center") ? vector3(s, "center", sw, std::nullopt, 1e3) : Eigen::Vector3d(shape.center * kMetresPerMm);
    if (member(s, "angles_deg"))
      shape.rotation = geometry::rotationFromAngles(kDegree * vector3(s, "angles_deg", sw, std::nullopt, 3600));
    return contact::makeConvexShape(shape.center, shape.rotation, shape.radii, shape.exponents);
  } catch (const Error& e) {
    throw InputError(sw + ": " + e.what());
  }
}

contact::ConvexShape readShape(const json& s, const std::string& sw, const std::filesystem::path& folder) {
  if (member(s, "fits")) onlyKeys(s, sw, {"model", "fits", "center", "angles_deg"});
  else onlyKeys(s, sw, {"model", "radii", "exponents", "center", "angles_deg"});
  const std::string model = text(s, "model", sw, std::nullopt);
  if (model != "sphere" && model != "ellipsoid" && model != "superellipsoid")
    refuse(sw, "model", "sphere, ellipsoid or superellipsoid", s.at("model"));
  if (member(s, "fits")) return readFittedShape(s, sw, model, folder);
  const Eigen::Vector3d radii = vector3(s, "radii", sw, std::nullopt, 1e3);
  const Eigen::Vector3d exponents = vector3(s, "exponents", sw, Eigen::Vector3d::Constant(2.0), 1e3);
  if (model != "superellipsoid" && exponents != Eigen::Vector3d::Constant(2.0))
    refuse(sw, "exponents", "2, 2, 2 for a " + model, s.at("exponents"));
  if (model == "sphere" && !(radii.maxCoeff() == radii.minCoeff()))
    refuse(sw, "radii", "three equal radii for a sphere", s.at("radii"));
  const Eigen::Vector3d center = vector3(s, "center", sw, Eigen::Vector3d::Zero(), 1e3);
  const Eigen::Matrix3d rotation = geometry::rotationFromAngles(kDegree * vector3(s, "angles_deg", sw, Eigen::Vector3d::Zero(), 3600));
  try {
    return contact::makeConvexShape(center, rotation, radii, exponents);
  } catch (const Error& e) {
    throw InputError(sw + ": " + e.what());
  }
}

SceneContact readContact(const json& j, const std::string& where, const std::vector<SceneBody>& bodies,
                         const std::filesystem::path& folder) {
  if (!j.is_object()) refuse(where, "contact", "an object", j);
  SceneContact c;
  onlyKeys(j, where, {"body", "point", "shape", "against", "normal_law", "friction"});
  const std::string body = text(j, "body", where, std::nullopt);
  c.body = bodyIndex(body, bodies);
  if (c.body < 0) throw InputError(where + ": body \"" + excerpt(body) + "\" is not one of the scene's bodies");
  if (member(j, "point") && member(j, "shape")) throw InputError(where + ": either \"shape\" or \"point\", not both");
  c.point_contact = member(j, "point") != nullptr;
  if (c.point_contact) c.station = vector3(j, "point", where, std::nullopt, 1e3);
  else c.shape = readShape(object(j, "shape", where), where + " shape", folder);
  const bool centred_sphere = c.shape.quadric && c.shape.radii.minCoeff() == c.shape.radii.maxCoeff() &&
                              c.shape.center == Eigen::Vector3d::Zero();
  const json& against = object(j, "against", where);
  onlyKeys(against, where + " against", {"plane", "cavity", "body", "shape"});
  if (const json* plane = member(against, "plane")) {
    const std::string pw = where + " against plane";
    if (!plane->is_object()) refuse(where, "against plane", "an object", *plane);
    onlyKeys(*plane, pw, {"point", "normal"});
    c.point = vector3(*plane, "point", pw, Eigen::Vector3d::Zero());
    c.normal = vector3(*plane, "normal", pw, std::nullopt);
    if (!(c.normal.norm() > 0)) refuse(pw, "normal", "a non-zero vector", plane->at("normal"));
  } else if (c.point_contact) {
    throw InputError(where + ": against: a contact point meets a plane only ({\"plane\": ...}), found " +
                     describeJson(against));
  } else if (const json* cavity = member(against, "cavity")) {
    const std::string cw = where + " against cavity";
    if (!cavity->is_object()) refuse(where, "against cavity", "an object", *cavity);
    onlyKeys(*cavity, cw, member(*cavity, "radii") ? std::initializer_list<std::string_view>{"center", "radii", "angles_deg"}
                                                   : std::initializer_list<std::string_view>{"center", "radius"});
    if (!centred_sphere)
      throw InputError(cw + ": a cavity holds a sphere centred at its body's origin (shape center [0, 0, 0])");
    c.cavity = true;
    c.point = vector3(*cavity, "center", cw, std::nullopt);
    if (member(*cavity, "radii")) {
      // An ellipsoidal cavity: no tighter anywhere than the ball, or it would touch in two places.
      c.ellipsoidal_cavity = true;
      const Eigen::Vector3d radii = vector3(*cavity, "radii", cw, std::nullopt, 1e6);
      const Eigen::Matrix3d rotation =
          geometry::rotationFromAngles(kDegree * vector3(*cavity, "angles_deg", cw, Eigen::Vector3d::Zero(), 3600));
      try {
        c.cavity_shape = contact::makeConvexShape(c.point, rotation, radii);
      } catch (const Error& e) {
        throw InputError(cw + ": " + e.what());
      }
      const double tightest = radii.minCoeff() * radii.minCoeff() / radii.maxCoeff();
      if (!(c.shape.radii[0] <= tightest))
        refuse(cw, "radii", "a cavity whose tightest radius of curvature (a_min^2 / a_max = " + excerpt(std::to_string(tightest)) +
                                ") holds the sphere", cavity->at("radii"));
    } else {
      c.cavity_radius = number(*cavity, "radius", cw, std::nullopt, c.shape.radii[0] * (1 + 1e-9), 1e6,
                               "a radius larger than the sphere's");
    }
  } else if (const json* other = member(against, "body")) {
    const std::string ow = where + " against";
    if (!other->is_string()) refuse(ow, "body", "a body's name", *other);
    c.other_body = bodyIndex(other->get<std::string>(), bodies);
    if (c.other_body < 0 || c.other_body == c.body)
      throw InputError(ow + ": body \"" + excerpt(other->get<std::string>()) + "\" is not another of the scene's bodies");
    c.other_shape = readShape(object(against, "shape", ow), ow + " shape", folder);
  } else {
    throw InputError(where + ": against: expected {\"plane\": ...}, {\"cavity\": ...} or {\"body\": ..., \"shape\": ...}, found " +
                     describeJson(against));
  }
  c.laws = readLaws(j, where);
  try {
    c.laws.normal.validate();
    c.laws.friction.validate();
  } catch (const Error& e) {
    throw InputError(where + ": " + e.what());
  }
  return c;
}

}  // namespace

Scene sceneFromJson(const json& document, const std::string& where, const std::filesystem::path& folder) {
  if (!document.is_object()) refuse(where, "scene", "a JSON object", document);
  Scene scene;
  onlyKeys(document, where, {"description", "gravity", "duration", "output_interval", "integrator", "bodies", "contacts"});
  if (const json* d = member(document, "description"); d && !d->is_string()) refuse(where, "description", "a string", *d);
  scene.gravity = vector3(document, "gravity", where, Eigen::Vector3d(0, 0, -9.81), 1e4);
  scene.duration = number(document, "duration", where, std::nullopt, 1e-9, 1e5, "a duration of up to 1e5 s");
  scene.output_interval = number(document, "output_interval", where, 0.01, 1e-9, 1e5, "an interval > 0 (s)");
  if (scene.duration / scene.output_interval > 1e6)
    throw InputError(where + ": output_interval: more than 1e6 output rows (duration / output_interval)");
  if (const json* in = member(document, "integrator")) {
    const std::string w = where + " integrator";
    if (!in->is_object()) refuse(where, "integrator", "an object", *in);
    onlyKeys(*in, w, {"type", "accuracy"});
    const std::string type = text(*in, "type", w, "runge-kutta-merson");
    if (type == "runge-kutta-merson") scene.integrator = IntegratorKind::RungeKuttaMerson;
    else if (type == "cpodes") scene.integrator = IntegratorKind::CPodes;
    else if (type == "semi-explicit-euler") scene.integrator = IntegratorKind::SemiExplicitEuler;
    else refuse(w, "type", "runge-kutta-merson, cpodes or semi-explicit-euler", in->at("type"));
    scene.accuracy = number(*in, "accuracy", w, 1e-6, 1e-14, 1, "an accuracy in [1e-14, 1]");
  }
  const json* bodies = member(document, "bodies");
  if (!bodies || !bodies->is_array() || bodies->empty() || bodies->size() > 1000)
    throw InputError(where + ": bodies: expected an array of 1 to 1000 bodies, found " +
                     (bodies ? describeJson(*bodies) : std::string("nothing")));
  for (size_t i = 0; i < bodies->size(); ++i) {
    scene.bodies.push_back(readBody((*bodies)[i], where + " bodies[" + std::to_string(i) + "]", scene.bodies));
    for (size_t k = 0; k < i; ++k)
      if (scene.bodies[k].name == scene.bodies[i].name)
        throw InputError(where + ": bodies[" + std::to_string(i) + "]: the name \"" + excerpt(scene.bodies[i].name) +
                         "\" is taken by bodies[" + std::to_string(k) + "]");
  }
  if (const json* contacts = member(document, "contacts")) {
    if (!contacts->is_array() || contacts->size() > 10000)
      refuse(where, "contacts", "an array of up to 10000 contacts", *contacts);
    for (size_t i = 0; i < contacts->size(); ++i)
      scene.contacts.push_back(readContact((*contacts)[i], where + " contacts[" + std::to_string(i) + "]", scene.bodies, folder));
  }
  return scene;
}

Scene readScene(const std::filesystem::path& path) {
  return sceneFromJson(readJsonFile(path, "scene"), path.string(), path.parent_path());
}

}  // namespace articula::dynamics
