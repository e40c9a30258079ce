#include "icef/app/view_app.h"

#include <array>
#include <cstdlib>
#include <string_view>
#include <system_error>
#include <vector>

#include "icef/core/parallel.h"
#include "icef/face/arkit_curves.h"
#include "icef/face/ict_model.h"
#include "icef/io/atomic_file.h"
#include "icef/io/json_util.h"
#include "icef/mesh/glb.h"
#include "icef/model/trained_model.h"

// Last: it brings <resolv.h>, whose _res macro breaks Eigen's headers included after it.
#include <httplib.h>

namespace icef {

namespace {

namespace fs = std::filesystem;

// web/viewer/index.html, built in (src/icef/app/module.cmake).
constexpr std::string_view kViewerHtml =
#include "icef/app/viewer_html.inc"
    ;

// The files of the npm package `three` the page imports: (path in the package, path in the folder).
constexpr std::array<std::array<const char*, 2>, 7> kThreeFiles = {{
    {"build/three.module.js", "three/three.module.js"},
    {"build/three.core.js", "three/three.core.js"},
    {"examples/jsm/loaders/GLTFLoader.js", "three/addons/loaders/GLTFLoader.js"},
    {"examples/jsm/controls/OrbitControls.js", "three/addons/controls/OrbitControls.js"},
    {"examples/jsm/utils/BufferGeometryUtils.js", "three/addons/utils/BufferGeometryUtils.js"},
    {"examples/jsm/utils/SkeletonUtils.js", "three/addons/utils/SkeletonUtils.js"},
    {"LICENSE", "three/LICENSE"},
}};

fs::path ThreeDir() {
  const char* env = std::getenv("ICEF_THREE_DIR");
  return env != nullptr && *env != '\0' ? fs::path(env) : fs::path(kThreeDir);
}

Status CopyThree(const fs::path& dest) {
  const fs::path three = ThreeDir();
  for (const auto& [from, to] : kThreeFiles) {
    std::error_code ec;
    if (!fs::is_regular_file(three / from, ec))
      return Status::Error(
          (three / from).string() +
          ": not found; three.js is installed by scripts/install-deps.sh (or set ICEF_THREE_DIR)");
    fs::create_directories((dest / to).parent_path(), ec);
    fs::copy_file(three / from, dest / to, fs::copy_options::overwrite_existing, ec);
    if (ec) return Status::Error((dest / to).string() + ": cannot write: " + ec.message());
  }
  return Status::Ok();
}

// The dataset cameras of the model's training frames, as the page takes them (upright: fl_y > 0).
Json CamerasJson(const ModelSetup& setup) {
  Json cameras = Json::array();
  for (size_t k = 0; k < setup.training_cameras.size(); ++k) {
    const Camera& given = setup.training_cameras[k];
    const Camera c = Camera::Upright(given.intrinsics(), given.world_from_cam());
    const Intrinsics& in = c.intrinsics();
    Json m = Json::array();
    for (int r = 0; r < 4; ++r)
      m.push_back({c.world_from_cam()(r, 0), c.world_from_cam()(r, 1), c.world_from_cam()(r, 2),
                   c.world_from_cam()(r, 3)});
    cameras.push_back({{"name", "train:" + std::to_string(k)},
                       {"transform_matrix", m},
                       {"w", in.width},
                       {"h", in.height},
                       {"fl_x", in.fl_x},
                       {"fl_y", in.fl_y},
                       {"cx", in.cx},
                       {"cy", in.cy}});
  }
  return cameras;
}

bool IsViewerFolder(const fs::path& dir) {
  std::error_code ec;
  return fs::is_regular_file(dir / "index.html", ec) && fs::is_regular_file(dir / "viewer.json", ec);
}

// The folder's contents into `tmp`: the GLB (exported or copied), three.js, the page, viewer.json.
Status FillFolder(const ViewAppOptions& o, const fs::path& tmp, std::ostream& out) {
  Json viewer = {{"title", o.input.filename().string()},
                 {"glb", "avatar.glb"},
                 {"background", {1.0, 1.0, 1.0}},
                 {"cameras", Json::array()},
                 {"curves", nullptr}};
  std::error_code ec;
  // three.js and the curves first: a missing install or a bad CSV is found before the export.
  ICEF_RETURN_IF_ERROR(CopyThree(tmp));
  if (o.curves) {
    ICEF_ASSIGN_OR_RETURN(const std::shared_ptr<const face::IctModel> ict, face::IctModel::LoadDefault());
    ICEF_ASSIGN_OR_RETURN(const face::ArkitCurves curves, face::ReadArkitCurves(*ict, *o.curves));
    fs::copy_file(*o.curves, tmp / "curves.csv", ec);
    if (ec) return Status::Error((tmp / "curves.csv").string() + ": cannot write: " + ec.message());
    viewer["curves"] = "curves.csv";
    out << "curves: " << curves.weights.size() << " frames from " << o.curves->string() << "\n";
  }
  if (o.input.extension() == ".glb") {
    ICEF_RETURN_IF_ERROR(mesh::ReadGlbSummary(o.input).status());
    fs::copy_file(o.input, tmp / "avatar.glb", ec);
    if (ec) return Status::Error((tmp / "avatar.glb").string() + ": cannot write: " + ec.message());
  } else {
    ExportAppOptions e = o.export_options;
    e.model = o.input;
    e.out = tmp / "avatar.glb";
    ICEF_RETURN_IF_ERROR(e.Validate());
    ICEF_ASSIGN_OR_RETURN(const TrainedModel loaded, LoadTrainedModel(o.input, Executor(e.threads)));
    ICEF_ASSIGN_OR_RETURN(const ExportSummary s, ExportLoadedModel(loaded, e, out));
    out << "exported the avatar: " << s.vertices << " vertices, " << s.triangles << " triangles, "
        << s.targets.size() << " morph targets\n";
    if (!s.note.empty()) out << "note: " << s.note << "\n";
    const ModelSetup& setup = loaded.model->setup();
    viewer["cameras"] = CamerasJson(setup);
    viewer["background"] = {setup.background.x(), setup.background.y(), setup.background.z()};
  }
  ICEF_RETURN_IF_ERROR(WriteFileAtomic(tmp / "index.html", kViewerHtml));
  return WriteFileAtomic(tmp / "viewer.json", viewer.dump(1) + "\n");
}

}  // namespace

Status RunView(const ViewAppOptions& o, std::ostream& out) {
  std::error_code ec;
  if (!fs::exists(o.input, ec)) return Status::Error(o.input.string() + ": no such file or directory");
  if (o.serve && o.out.empty()) {
    if (!IsViewerFolder(o.input))
      return Status::Error(o.input.string() +
                           ": not a viewer folder (no index.html and viewer.json); give "
                           "--out DIR to make one from a model or GLB");
    return ServeFolder(o.input, o.port, [&](const std::string& url) {
      out << "serving " << o.input.string() << " at " << url << " (Ctrl-C stops)" << std::endl;
    });
  }
  if (o.out.empty())
    return Status::Error("icef view: --out DIR is required (or --serve with a viewer folder)");
  if (IsViewerFolder(o.input))
    return Status::Error(o.input.string() + ": a viewer folder already; --serve serves it");
  ICEF_RETURN_IF_ERROR(
      CreateDirectoryAtomic(o.out, [&](const fs::path& tmp) { return FillFolder(o, tmp, out); }));
  out << "wrote " << o.out.string() << ": index.html, avatar.glb, viewer.json, three.js\n";
  if (!o.serve) return Status::Ok();
  return ServeFolder(o.out, o.port, [&](const std::string& url) {
    out << "serving " << o.out.string() << " at " << url << " (Ctrl-C stops)" << std::endl;
  });
}

Status ServeFolder(const fs::path& dir, int port, const std::function<void(const std::string&)>& on_listen) {
  httplib::Server server;
  server.set_mount_point("/", dir.string());
  server.set_file_extension_and_mimetype_mapping("glb", "model/gltf-binary");
  server.set_file_extension_and_mimetype_mapping("csv", "text/csv");
  const int bound =
      port == 0 ? server.bind_to_any_port("127.0.0.1") : (server.bind_to_port("127.0.0.1", port) ? port : -1);
  if (bound <= 0)
    return Status::Error("icef view --serve: cannot listen on 127.0.0.1:" + std::to_string(port) +
                         " (in use? --port 0 takes any free port)");
  if (on_listen) on_listen("http://127.0.0.1:" + std::to_string(bound) + "/index.html");
  if (!server.listen_after_bind()) return Status::Error("icef view --serve: the server stopped");
  return Status::Ok();
}

}  // namespace icef
