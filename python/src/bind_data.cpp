// Cameras, datasets and the built-in synthetic scenes.
#include <memory>
#include <sstream>

#include "geometry/camera/camera.h"
#include "geometry/scene/dataset_checks.h"
#include "geometry/scene/scene.h"
#include "geometry/synth/assets.h"
#include "geometry/synth/synthetic_scene.h"
#include "geometry/synth/write_dataset.h"
#include "python/src/bindings.h"

namespace saresgs::python {

namespace {

const SceneView& viewAt(const Scene& s, int i) {
  if (i < 0 || i >= static_cast<int>(s.views.size()))
    throw py::index_error("view " + std::to_string(i) + " outside 0.." + std::to_string(s.views.size()) +
                          " (the dataset's views)");
  return s.views[static_cast<std::size_t>(i)];
}

Eigen::Matrix4d worldToCamera(const Camera& c) {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.topLeftCorner<3, 3>() = c.R;
  m.topRightCorner<3, 1>() = c.t;
  return m;
}

}  // namespace

void bindData(py::module_& m) {
  py::class_<Camera>(
      m, "Camera",
      "A pinhole camera in the COLMAP/OpenCV convention: x_cam = R x_world + t, x right, y down, z forward; "
      "pixel (i, j) covers [i, i+1) x [j, j+1).")
      .def(py::init([](int width, int height, double fx, double fy, double cx, double cy, const Eigen::Matrix3d& R,
                       const Eigen::Vector3d& t) {
             Camera c;
             c.K = {width, height, fx, fy, cx, cy};
             c.R = R;
             c.t = t;
             validateCamera(c, "Camera", "arguments");
             return c;
           }),
           py::arg("width"), py::arg("height"), py::arg("fx"), py::arg("fy"), py::arg("cx"), py::arg("cy"),
           py::arg("R") = Eigen::Matrix3d::Identity(), py::arg("t") = Eigen::Vector3d::Zero(),
           "Intrinsics in pixels; R (3x3 rotation) and t (3,) map world to camera.")
      .def_static(
          "look_at",
          [](int width, int height, double fx, double fy, const Eigen::Vector3d& eye, const Eigen::Vector3d& target,
             const Eigen::Vector3d& up) {
            return Camera::lookAt({width, height, fx, fy, width / 2.0, height / 2.0}, eye, target, up);
          },
          py::arg("width"), py::arg("height"), py::arg("fx"), py::arg("fy"), py::arg("eye"), py::arg("target"),
          py::arg("up") = Eigen::Vector3d::UnitZ(),
          "A camera at `eye` looking at `target`, principal point at the centre.")
      .def_property_readonly("width", [](const Camera& c) { return c.K.width; })
      .def_property_readonly("height", [](const Camera& c) { return c.K.height; })
      .def_property_readonly("fx", [](const Camera& c) { return c.K.fx; })
      .def_property_readonly("fy", [](const Camera& c) { return c.K.fy; })
      .def_property_readonly("cx", [](const Camera& c) { return c.K.cx; })
      .def_property_readonly("cy", [](const Camera& c) { return c.K.cy; })
      .def_property_readonly(
          "K", [](const Camera& c) { return c.K.matrix(); }, "3x3 intrinsic matrix")
      .def_readwrite("R", &Camera::R, "3x3 world-to-camera rotation")
      .def_readwrite("t", &Camera::t, "world-to-camera translation (3,)")
      .def_property_readonly("world_to_camera", &worldToCamera, "4x4 world-to-camera transform [R t; 0 1]")
      .def_property_readonly("center", &Camera::center, "camera centre in world coordinates (3,)")
      .def_property_readonly(
          "fov", [](const Camera& c) { return py::make_tuple(c.K.fovX(), c.K.fovY()); },
          "horizontal and vertical field of view, radians")
      .def(
          "project",
          [](const Camera& c, const Eigen::Vector3d& x) -> py::object {
            const auto uv = c.project(x);
            if (!uv) return py::none();
            return py::cast(Eigen::Vector2d(*uv));
          },
          py::arg("x"), "Pixel coordinates of world point x, or None at or behind the camera plane.")
      .def("__repr__", [](const Camera& c) {
        std::ostringstream s;
        s << "Camera(" << c.K.width << "x" << c.K.height << ", fx " << c.K.fx << ", centre " << c.center().transpose()
          << ")";
        return s.str();
      });

  py::class_<Scene, std::shared_ptr<Scene>>(
      m, "Dataset",
      "A loaded dataset: views (cameras and lazily read images), the train/test split and the SfM points.")
      .def_readonly("source", &Scene::source, "the folder it was loaded from")
      .def_property_readonly(
          "names",
          [](const Scene& s) {
            std::vector<std::string> v;
            for (const auto& x : s.views) v.push_back(x.name);
            return v;
          },
          "image names, by view index")
      .def_readonly("train", &Scene::train, "indices of the train views (the candidates of an active run)")
      .def_readonly("test", &Scene::test, "indices of the test views")
      .def("__len__", [](const Scene& s) { return s.views.size(); })
      .def(
          "camera", [](const Scene& s, int i) { return viewAt(s, i).camera; }, py::arg("view"), "the camera of a view")
      .def_property_readonly(
          "cameras",
          [](const Scene& s) {
            std::vector<Camera> v;
            for (const auto& x : s.views) v.push_back(x.camera);
            return v;
          },
          "every view's camera, by view index")
      .def(
          "image",
          [](const std::shared_ptr<Scene>& s, int i) {
            const SceneView& v = viewAt(*s, i);
            (void)v;
            const Image8* img;
            {
              py::gil_scoped_release nogil;
              img = &s->image(i);
            }
            // A read-only view of the dataset's cached pixels, kept alive by the dataset.
            py::array_t<std::uint8_t> a({img->height, img->width, img->channels}, img->data.data(), py::cast(s));
            py::detail::array_proxy(a.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
            return a;
          },
          py::arg("view"), "the view's image, H x W x 3 uint8 (read-only, no copy)")
      .def(
          "image_float",
          [](const Scene& s, int i) {
            (void)viewAt(s, i);
            return imageArray(s.imageFloat(i));
          },
          py::arg("view"), "the view's image, H x W x 3 float32 in [0, 1]")
      .def(
          "has_depth",
          [](const Scene& s, int i) {
            (void)viewAt(s, i);
            return s.hasDepth(i);
          },
          py::arg("view"))
      .def(
          "depth",
          [](const Scene& s, int i) {
            (void)viewAt(s, i);
            return imageArray(s.depth(i));
          },
          py::arg("view"),
          "ground-truth depth (z along the camera axis), H x W float32; raises when the dataset has none")
      .def_property_readonly(
          "points",
          [](const Scene& s) {
            std::vector<double> xyz;
            xyz.reserve(s.points.size() * 3);
            for (const auto& p : s.points) xyz.insert(xyz.end(), {p.xyz.x(), p.xyz.y(), p.xyz.z()});
            return ownedArray(std::move(xyz), {static_cast<py::ssize_t>(s.points.size()), 3});
          },
          "SfM points, N x 3 float64")
      .def_property_readonly(
          "point_colors",
          [](const Scene& s) {
            std::vector<std::uint8_t> rgb;
            rgb.reserve(s.points.size() * 3);
            for (const auto& p : s.points) rgb.insert(rgb.end(), p.rgb.begin(), p.rgb.end());
            return ownedArray(std::move(rgb), {static_cast<py::ssize_t>(s.points.size()), 3});
          },
          "SfM point colours, N x 3 uint8")
      .def_readonly("extent", &Scene::extent,
                    "3DGS scene scale (1.1 x the train cameras' largest distance from their mean)")
      .def_property_readonly(
          "frame_center", [](const Scene& s) { return s.frame.center; },
          "the frame the dataset is computed in: world = internal * frame_scale + frame_center; "
          "cameras, points and extent are internal, .ply files world (the identity for a scene "
          "of metres about the origin)")
      .def_property_readonly(
          "frame_scale", [](const Scene& s) { return s.frame.scale; }, "see frame_center")
      .def_property_readonly(
          "background",
          [](const Scene& s) -> py::object {
            if (!s.background) return py::none();
            return py::make_tuple((*s.background)[0], (*s.background)[1], (*s.background)[2]);
          },
          "the colour behind the content (RGBA images are composited on it, renders are against it); None: the data "
          "has none")
      .def_readonly("random_background", &Scene::random_background, "training draws a fresh background colour per step")
      .def_readonly("background_from", &Scene::background_from, "where the background came from")
      .def(
          "warnings",
          [](const Scene& s) {
            std::vector<std::string> v;
            for (const DatasetWarning& w : checkDataset(s)) v.push_back(w.view + ": " + w.field + ": " + w.message);
            return v;
          },
          "the dataset checks' warnings (fields of view, principal points, views that see no point)")
      .def("__repr__", [](const Scene& s) {
        return "Dataset('" + s.source + "', " + std::to_string(s.views.size()) +
               " views: " + std::to_string(s.train.size()) + " train, " + std::to_string(s.test.size()) + " test, " +
               std::to_string(s.points.size()) + " points)";
      });

  m.def(
      "load_dataset",
      [](const std::string& path, int downscale, int test_every, const py::object& background) {
        DatasetOptions o;
        o.load.downscale = downscale;
        o.test_every = test_every;
        o.background = backgroundArg(background);
        std::shared_ptr<Scene> s;
        std::vector<DatasetWarning> warnings;
        {
          py::gil_scoped_release nogil;
          s = std::make_shared<Scene>(loadDataset(path, o));
          if (o.background) s->background_from = "background=";  // said here, not by the CLI's option
          warnings = checkDataset(*s);  // refuses a dataset that no train view sees (InputError)
        }
        // As the command line prints them: implausible intrinsics, views that see no point.
        if (!warnings.empty() &&
            PyErr_WarnEx(PyExc_UserWarning, (path + ":\n" + formatWarnings(warnings)).c_str(), 1) != 0)
          throw py::error_already_set();
        if (const std::string w = backgroundWarning(*s);
            !w.empty() && PyErr_WarnEx(PyExc_UserWarning, w.c_str(), 1) != 0)
          throw py::error_already_set();
        return s;
      },
      py::arg("path"), py::arg("downscale") = 1, py::arg("test_every") = 8, py::arg("background") = py::none(),
      "Loads a COLMAP, Blender (transforms_train.json), nerfstudio (transforms.json) or `saresgs scene` folder. "
      "background: None (what the data says: a manifest, Blender's white, white for images with alpha), 'white', "
      "'black', 'random' (a fresh colour per training step, evaluated on white), 'R,G,B' or three numbers in 0..1.");

  m.def(
      "make_scene",
      [](const std::string& layout, const std::string& out, int width, int height, std::uint64_t seed, int views) {
        SyntheticOptions o = syntheticOptions(layout, width, height, seed, views);
        py::gil_scoped_release nogil;
        for (auto& mesh : o.meshes) mesh = resolveAsset(mesh);
        const SyntheticScene scene = makeSyntheticScene(o);
        WriteDatasetOptions w;
        w.simulated.seed = seed;
        writeSyntheticDataset(scene, out, w);
        return std::make_shared<Scene>(loadDataset(out));
      },
      py::arg("layout"), py::arg("out"), py::arg("width") = 256, py::arg("height") = 192, py::arg("seed") = 0,
      py::arg("views") = 0,
      "Writes a built-in synthetic scene (`saresgs scene`: object, room360, unbalanced, tworooms or corridor) as a "
      "COLMAP "
      "folder at `out` and loads it.");
}

std::optional<BackgroundChoice> backgroundArg(const py::object& value) {
  if (value.is_none()) return std::nullopt;
  if (py::isinstance<py::str>(value)) return parseBackground(value.cast<std::string>(), "background");
  std::vector<double> c;
  try {
    c = value.cast<std::vector<double>>();
  } catch (const py::cast_error&) {
    throw py::type_error("background: expected None, a string (" + std::string(kBackgroundForms) +
                         ") or three numbers");
  }
  if (c.size() != 3 || !(c[0] >= 0 && c[0] <= 1 && c[1] >= 0 && c[1] <= 1 && c[2] >= 0 && c[2] <= 1))
    throw py::value_error("background: expected three numbers in 0..1");
  return BackgroundChoice{false, {static_cast<float>(c[0]), static_cast<float>(c[1]), static_cast<float>(c[2])}};
}

std::shared_ptr<Scene> withBackground(const std::shared_ptr<Scene>& dataset, const py::object& background) {
  const std::optional<BackgroundChoice> b = backgroundArg(background);
  if (!b) return dataset;
  auto copy = std::make_shared<Scene>(*dataset);
  setBackground(*copy, *b, "background=");
  return copy;
}

}  // namespace saresgs::python
