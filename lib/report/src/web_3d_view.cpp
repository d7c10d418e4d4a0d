#include "articula/report/web_3d_view.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>

#include <nlohmann/json.hpp>

#include "articula/report/diverging_colour.hpp"
#include "articula/report/slice_image.hpp"
#include "three_js.hpp"

namespace articula::report {
namespace {

using nlohmann::json;

// Little-endian typed arrays as base64: what the page turns back into
// Float32Array / Uint32Array / Uint8Array without parsing numbers.
template <typename T>
std::string packed(const std::vector<T>& values) {
  std::string bytes(values.size() * sizeof(T), '\0');
  if (!values.empty()) std::memcpy(bytes.data(), values.data(), bytes.size());
  return base64(bytes);
}

std::string positionsAbout(const Eigen::MatrixX3d& vertices, const Eigen::Vector3d& centre) {
  std::vector<float> xyz;
  xyz.reserve(static_cast<size_t>(vertices.rows()) * 3);
  for (Eigen::Index i = 0; i < vertices.rows(); ++i)
    for (int k = 0; k < 3; ++k) xyz.push_back(static_cast<float>(vertices(i, k) - centre[k]));
  return packed(xyz);
}

json surfaceJson(const ViewSurface& surface, const Eigen::Vector3d& centre) {
  std::vector<std::uint32_t> indices;
  indices.reserve(static_cast<size_t>(surface.triangles.rows()) * 3);
  for (Eigen::Index i = 0; i < surface.triangles.rows(); ++i)
    for (int k = 0; k < 3; ++k) indices.push_back(static_cast<std::uint32_t>(surface.triangles(i, k)));
  return {{"name", surface.name},
          {"positions", positionsAbout(surface.vertices, centre)},
          {"indices", packed(indices)}};
}

json colouringJson(const ViewModelDistances& d, double shared_range_mm) {
  const double range = shared_range_mm > 0 ? shared_range_mm : symmetricColourRange(d.signed_distance_mm);
  std::vector<std::uint8_t> colours;
  colours.reserve(static_cast<size_t>(d.signed_distance_mm.size()) * 3);
  for (Eigen::Index i = 0; i < d.signed_distance_mm.size(); ++i)
    for (const std::uint8_t c : divergingRgb(d.signed_distance_mm[i] / range)) colours.push_back(c);
  return {{"model", d.model}, {"range_mm", range}, {"colours", packed(colours)}};
}

// The colour bar's gradient: the scale is piecewise linear between these stops.
std::string colourBarGradient() {
  std::string css = "linear-gradient(to right";
  for (const double t : {-1.0, -0.5, 0.0, 0.5, 1.0}) css += "," + divergingColour(t);
  return css + ")";
}

constexpr const char* kViewScript = R"JS(
(function () {
  var section = document.getElementById('view3d');
  var canvas = document.getElementById('view3d-canvas');
  var note = document.getElementById('view3d-note');
  var data = JSON.parse(document.getElementById('view3d-data').textContent);
  function bytes(b64) {
    var s = atob(b64), u = new Uint8Array(s.length);
    for (var i = 0; i < s.length; ++i) u[i] = s.charCodeAt(i);
    return u;
  }
  function floats(b64) { return new Float32Array(bytes(b64).buffer); }
  function indices(b64) { return new Uint32Array(bytes(b64).buffer); }
  var renderer;
  try {
    renderer = new THREE.WebGLRenderer({canvas: canvas, antialias: true, preserveDrawingBuffer: true});
  } catch (e) {
    note.textContent = 'The 3-D view needs WebGL, which this browser does not offer (' + e.message + ').';
    canvas.style.display = 'none';
    return;
  }
  var background = 0x20232a;
  renderer.setClearColor(background);
  renderer.setPixelRatio(window.devicePixelRatio || 1);
  renderer.setSize(canvas.clientWidth, canvas.clientHeight, false);
  var scene = new THREE.Scene();
  var R = data.radius_mm;
  var camera = new THREE.PerspectiveCamera(35, canvas.clientWidth / canvas.clientHeight, R / 50, R * 100);
  // From the front (LPS: anterior is -y), head up (+z): the patient's left
  // on the right, as in the radiological slices above.
  // At 4 radii a 35-degree view spans 1.26 radii either side of the
  // centre: the head fills four fifths of the canvas, its neck in view.
  camera.up.set(0, 0, 1);
  camera.position.set(0, -4 * R, 0);
  camera.lookAt(0, 0, 0);
  scene.add(new THREE.AmbientLight(0xffffff, 0.45));
  var light = new THREE.DirectionalLight(0xffffff, 0.65);
  camera.add(light);
  scene.add(camera);
  function mesh(surface, colour, opacity) {
    var g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.BufferAttribute(floats(surface.positions), 3));
    g.setIndex(new THREE.BufferAttribute(indices(surface.indices), 1));
    g.computeVertexNormals();
    var m = new THREE.MeshPhongMaterial({color: colour, side: THREE.DoubleSide, transparent: opacity < 1,
                                         opacity: opacity, depthWrite: opacity >= 1, shininess: 20});
    var object = new THREE.Mesh(g, m);
    scene.add(object);
    return object;
  }
  var toggles = document.getElementById('view3d-toggles');
  function toggle(label, object, checked) {
    var box = document.createElement('input');
    box.type = 'checkbox';
    box.checked = checked;
    object.visible = checked;
    box.addEventListener('change', function () { object.visible = box.checked; render(); });
    var l = document.createElement('label');
    l.appendChild(box);
    l.appendChild(document.createTextNode(' ' + label));
    toggles.appendChild(l);
  }
  if (data.bone) toggle('bone', mesh(data.bone, 0xe3d6b8, 0.35), true);
  if (data.departures) toggle('departing from the model', mesh(data.departures, 0xd62728, 0.9), true);
  var palette = [0x4daf4a, 0xff7f00, 0x984ea3, 0xa65628, 0xe7298a, 0x999999];
  data.surfaces.forEach(function (s, i) {
    toggle(s.name + ' (fitted)', mesh(s, palette[i % palette.length], 0.3), false);
  });
  var cloud = null, chooser = document.getElementById('view3d-colouring');
  if (data.points) {
    var g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.BufferAttribute(floats(data.points.positions), 3));
    cloud = new THREE.Points(g, new THREE.PointsMaterial({size: 4, sizeAttenuation: false, vertexColors: THREE.VertexColors}));
    cloud.renderOrder = 1;  // over the translucent surfaces
    scene.add(cloud);
    toggle('articular points', cloud, true);
    data.points.colourings.forEach(function (c) {
      var o = document.createElement('option');
      o.value = c.model;
      o.textContent = c.model;
      chooser.appendChild(o);
    });
    chooser.value = data.selected;
    chooser.addEventListener('change', function () { colourBy(chooser.value); render(); });
  }
  function colourBy(model) {
    var c = data.points.colourings.filter(function (x) { return x.model === model; })[0];
    if (!c) return;
    var rgb = bytes(c.colours), f = new Float32Array(rgb.length);
    for (var i = 0; i < rgb.length; ++i) f[i] = rgb[i] / 255;
    cloud.geometry.setAttribute('color', new THREE.BufferAttribute(f, 3));
    var r = c.range_mm.toFixed(c.range_mm < 0.1 ? 3 : 2);
    document.getElementById('view3d-min').textContent = '-' + r + ' mm (inside)';
    document.getElementById('view3d-max').textContent = '+' + r + ' mm (outside)';
  }
  if (cloud) colourBy(data.selected);
  var controls = new THREE.OrbitControls(camera, canvas);
  controls.addEventListener('change', render);
  function render() { renderer.render(scene, camera); }
  render();
  // The first frame's drawn pixels: what a check of the page reads.
  var gl = renderer.getContext(), w = gl.drawingBufferWidth, h = gl.drawingBufferHeight;
  var px = new Uint8Array(4 * w * h), drawn = 0;
  gl.readPixels(0, 0, w, h, gl.RGBA, gl.UNSIGNED_BYTE, px);
  var br = (background >> 16) & 255, bg = (background >> 8) & 255, bb = background & 255;
  for (var i = 0; i < px.length; i += 4)
    if (Math.abs(px[i] - br) + Math.abs(px[i + 1] - bg) + Math.abs(px[i + 2] - bb) > 24) ++drawn;
  canvas.setAttribute('data-rendered-pixels', String(drawn));
  section.setAttribute('data-ready', 'true');
})();
)JS";

}  // namespace

double symmetricColourRange(const Eigen::VectorXd& signed_distance_mm) {
  std::vector<double> magnitudes;
  for (Eigen::Index i = 0; i < signed_distance_mm.size(); ++i)
    if (std::isfinite(signed_distance_mm[i])) magnitudes.push_back(std::fabs(signed_distance_mm[i]));
  if (magnitudes.empty()) return 0.01;
  const size_t k = std::min(magnitudes.size() - 1, static_cast<size_t>(std::ceil(0.98 * static_cast<double>(magnitudes.size()))) - 1);
  std::nth_element(magnitudes.begin(), magnitudes.begin() + static_cast<std::ptrdiff_t>(k), magnitudes.end());
  return std::max(0.01, magnitudes[k]);
}

std::string web3dViewHtml(const View3d& view) {
  json data = {{"radius_mm", view.radius_mm}, {"selected", view.selected_model}, {"surfaces", json::array()}};
  if (view.bone.vertices.rows() > 0 && view.bone.triangles.rows() > 0) data["bone"] = surfaceJson(view.bone, view.centre);
  if (view.departures.vertices.rows() > 0 && view.departures.triangles.rows() > 0)
    data["departures"] = surfaceJson(view.departures, view.centre);
  for (const auto& s : view.fitted)
    if (s.vertices.rows() > 0 && s.triangles.rows() > 0) data["surfaces"].push_back(surfaceJson(s, view.centre));
  if (view.points.rows() > 0) {
    json colourings = json::array();
    for (const auto& d : view.distances)
      if (d.signed_distance_mm.size() == view.points.rows()) colourings.push_back(colouringJson(d, view.colour_range_mm));
    data["points"] = {{"positions", positionsAbout(view.points, view.centre)}, {"colourings", colourings}};
  }
  std::string data_text = data.dump();
  // JSON inside <script>: "</" would end the element.
  for (size_t at = data_text.find("</"); at != std::string::npos; at = data_text.find("</", at + 3))
    data_text.replace(at, 2, "<\\/");
  std::string html =
      "<section id=\"view3d\"><h2>3-D view</h2>\n"
      "<p class=\"note\">Drag to turn, scroll to zoom, right-drag to pan. Seen from the front, head up. Tick a fitted "
      "surface to show it. Red: where the bone departs from the selected model (see the departures' table). The points are coloured by their signed distance to the chosen model, on the "
      "error maps' scale where the report sets one (98 % of all models' distances within the bar; the rest saturate).</p>\n"
      "<style>#view3d-toggles label{white-space:nowrap;margin-right:.8em}</style>\n"
      "<div class=\"view3d-controls\"><span id=\"view3d-toggles\"></span> <label>colour points by <select "
      "id=\"view3d-colouring\"></select></label></div>\n"
      "<canvas id=\"view3d-canvas\" width=\"960\" height=\"600\" style=\"width:100%;max-width:960px;height:600px;"
      "display:block;background:#20232a\"></canvas>\n"
      "<div class=\"colour-bar\"><span id=\"view3d-min\"></span><span class=\"bar\" style=\"background:" +
      colourBarGradient() + "\"></span><span id=\"view3d-max\"></span></div>\n<p id=\"view3d-note\" class=\"note\"></p>\n";
  html += "<script type=\"application/json\" id=\"view3d-data\">" + data_text + "</script>\n";
  html += "<script>" + std::string(detail::threeJs()) + "\n</script>\n<script>" + std::string(detail::orbitControlsJs()) +
          "\n</script>\n<script>" + kViewScript + "</script>\n";
  return html + "</section>\n";
}

}  // namespace articula::report
