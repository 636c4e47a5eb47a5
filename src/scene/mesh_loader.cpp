// Mesh files through assimp, behind the checks of mesh_loader.hpp: assimp reads only what our IOSystem
// hands it, and that is only files admitted by the path confinement, read into memory first.
#include "vsd/scene/mesh_loader.hpp"

#include <assimp/IOSystem.hpp>
#include <assimp/MemoryIOWrapper.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <assimp/Importer.hpp>
#include <cctype>
#include <limits>
#include <list>
#include <string>
#include <vector>

#include "input_file.hpp"
#include "path_confinement.hpp"
#include "vsd/core/error.hpp"
#include "xml_guard.hpp"

namespace vsd::scene {

namespace fs = std::filesystem;

namespace {

std::string lower_extension(const fs::path& p) {
  std::string ext = p.extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

// The formats whose files vsd lets assimp read. Each is chosen by its extension alone (assimp picks the
// one importer that claims it, without trying others on the content), and each is either line or header
// based or XML behind check_xml_shape().
bool accepted_format(const std::string& ext) {
  return ext == ".stl" || ext == ".obj" || ext == ".dae" || ext == ".ply";
}

// Every file assimp asks for: the mesh itself (read before the import, served from memory) and whatever
// it pulls in, admitted by the confinement and read whole within the size limit. Refusals are collected
// as warnings; assimp sees a file it cannot open and goes on without it (an OBJ without its materials).
class ConfinedIOSystem : public Assimp::IOSystem {
 public:
  ConfinedIOSystem(const detail::PathConfinement& confinement, std::uintmax_t max_bytes, std::string main_path,
                   const std::string& main_bytes)
      : confinement_(confinement), max_bytes_(max_bytes), main_path_(std::move(main_path)), main_(main_bytes) {}

  bool Exists(const char* file) const override {
    if (file == main_path_) return true;
    fs::path resolved;
    std::string why;
    return confinement_.admit(file, resolved, why) == detail::PathConfinement::Verdict::Admitted;
  }

  char getOsSeparator() const override { return '/'; }

  Assimp::IOStream* Open(const char* file, const char* mode) override {
    if (mode == nullptr || mode[0] != 'r') return nullptr;  // importing never writes
    if (file == main_path_) return stream(main_);
    fs::path resolved;
    std::string why;
    switch (confinement_.admit(file, resolved, why)) {
      case detail::PathConfinement::Verdict::Missing:
        return nullptr;  // the importer says what it missed, if it cares
      case detail::PathConfinement::Verdict::Refused:
        warn("'" + std::string(file) + "', pulled in by the mesh, was not read: " + why);
        return nullptr;
      case detail::PathConfinement::Verdict::Admitted:
        break;
    }
    try {
      std::string bytes = detail::read_input(resolved, max_bytes_, "file pulled in by the mesh");
      if (lower_extension(resolved) == ".dae" || lower_extension(resolved) == ".xml")
        detail::check_xml_shape(bytes, resolved.string(), "XML file",
                                {max_mesh_xml_depth, max_mesh_xml_elements, max_bytes_});
      return stream(extra_.emplace_back(std::move(bytes)));
    } catch (const vsd::Error& e) {
      warn(std::string(e.what()) + "; not read");
      return nullptr;
    }
  }

  void Close(Assimp::IOStream* file) override { delete file; }

  std::vector<std::string> warnings;

 private:
  // Once each: importers try a file more than once.
  void warn(std::string text) {
    if (std::find(warnings.begin(), warnings.end(), text) == warnings.end()) warnings.push_back(std::move(text));
  }

  static Assimp::IOStream* stream(const std::string& bytes) {
    return new Assimp::MemoryIOStream(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size(), false);
  }

  const detail::PathConfinement& confinement_;
  std::uintmax_t max_bytes_;
  std::string main_path_;
  const std::string& main_;
  std::list<std::string> extra_;  // stable addresses: assimp reads through the streams until it closes them
};

}  // namespace

MeshReport load_mesh(Geometry& geometry, const fs::path& path, const MeshOptions& options) {
  const std::string where = "mesh '" + path.string() + "'";
  const std::string ext = lower_extension(path);
  if (!accepted_format(ext))
    vsd::detail::throw_error(where + ": format '" + ext +
                        "' is not read (vsd reads STL, OBJ, COLLADA (.dae) and PLY meshes)");
  std::vector<fs::path> roots = options.allowed_roots;
  if (roots.empty()) roots.push_back(fs::absolute(path).parent_path());
  const detail::PathConfinement confinement(roots, options.allow_paths_outside);
  fs::path file;
  std::string why;
  switch (confinement.admit(path, file, why)) {
    case detail::PathConfinement::Verdict::Missing:
      vsd::detail::throw_error(where + ": no such file");
    case detail::PathConfinement::Verdict::Refused:
      vsd::detail::throw_error(where + ": refused: " + why);
    case detail::PathConfinement::Verdict::Admitted:
      break;
  }
  const std::string bytes = detail::read_input(file, options.max_file_bytes, "mesh file");
  if (ext == ".dae") {
    detail::check_xml_shape(bytes, file.string(), "COLLADA mesh",
                            {max_mesh_xml_depth, max_mesh_xml_elements, options.max_file_bytes});
    detail::check_collada_instances(bytes, file.string(), max_mesh_collada_nodes, max_mesh_collada_values);
  }

  Assimp::Importer importer;
  auto* io = new ConfinedIOSystem(confinement, options.max_file_bytes, file.string(), bytes);
  importer.SetIOHandler(io);  // the importer owns it
  // Positions decide identity: normals are dropped before joining and regenerated smooth, so a cube is 8
  // vertices whether the file repeats them per facet (STL) or indexes them (OBJ). Node transforms are
  // baked in (COLLADA files place meshes in a node hierarchy).
  importer.SetPropertyInteger(AI_CONFIG_PP_RVC_FLAGS, aiComponent_NORMALS);
  const unsigned flags = aiProcess_Triangulate | aiProcess_RemoveComponent | aiProcess_JoinIdenticalVertices |
                         aiProcess_GenSmoothNormals | aiProcess_PreTransformVertices | aiProcess_SortByPType;
  const aiScene* scene = nullptr;
  try {
    scene = importer.ReadFile(file.string(), flags);
  } catch (const std::exception& e) {  // assimp catches most of its own; memory may still run out
    vsd::detail::throw_error(where + ": " + e.what());
  }
  if (scene == nullptr) vsd::detail::throw_error(where + ": " + importer.GetErrorString());
  MeshReport report;
  report.warnings = io->warnings;

  std::vector<Eigen::Vector3d> vertices;
  std::vector<Eigen::Vector3d> normals;
  std::vector<Eigen::Vector2d> uv;
  std::vector<std::int32_t> facets;
  bool all_uv = true;
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    const aiMesh* mesh = scene->mMeshes[m];
    if ((mesh->mPrimitiveTypes & aiPrimitiveType_TRIANGLE) == 0) continue;  // points and lines
    if (vertices.size() + mesh->mNumVertices >
        static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max()))
      vsd::detail::throw_error(where + ": more vertices than 32-bit indices can address");
    const auto base = static_cast<std::int32_t>(vertices.size());
    for (unsigned v = 0; v < mesh->mNumVertices; ++v) {
      const aiVector3D& p = mesh->mVertices[v];
      vertices.emplace_back(p.x, p.y, p.z);
      if (mesh->HasNormals()) {
        const aiVector3D& n = mesh->mNormals[v];
        normals.emplace_back(n.x, n.y, n.z);
      } else {
        normals.emplace_back(Eigen::Vector3d::Zero());
      }
      if (mesh->HasTextureCoords(0)) {
        const aiVector3D& t = mesh->mTextureCoords[0][v];
        uv.emplace_back(t.x, t.y);
      } else {
        all_uv = false;
        uv.emplace_back(Eigen::Vector2d::Zero());
      }
    }
    for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
      const aiFace& face = mesh->mFaces[f];
      if (face.mNumIndices != 3) continue;
      for (unsigned i = 0; i < 3; ++i) {
        if (face.mIndices[i] >= mesh->mNumVertices)  // a malformed file assimp passed on
          vsd::detail::throw_error(where + ": a face refers to vertex " + std::to_string(face.mIndices[i]) +
                              " of a mesh with " + std::to_string(mesh->mNumVertices));
        facets.push_back(base + static_cast<std::int32_t>(face.mIndices[i]));
      }
    }
  }
  if (facets.empty()) vsd::detail::throw_error(where + ": no triangles");
  if (!all_uv) uv.clear();  // texture coordinates only when every vertex has them

  geometry.set_kind(GeometryKind::Mesh);
  geometry.set_vertices(vertices);
  geometry.set_normals(normals);
  geometry.set_facets(facets);
  geometry.set_texture_coordinates(uv);
  return report;
}

}  // namespace vsd::scene
