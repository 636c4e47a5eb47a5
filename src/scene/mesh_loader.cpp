// Mesh files through assimp.
#include "vsd/scene/mesh_loader.hpp"

#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <assimp/Importer.hpp>
#include <limits>
#include <string>
#include <vector>

#include "vsd/core/error.hpp"

namespace vsd::scene {

void load_mesh(Geometry& geometry, const std::filesystem::path& path) {
  const std::string where = "mesh '" + path.string() + "'";
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) detail::throw_error(where + ": no such file");

  Assimp::Importer importer;
  // Positions decide identity: normals are dropped before joining and regenerated smooth, so a cube is 8
  // vertices whether the file repeats them per facet (STL) or indexes them (OBJ). Node transforms are
  // baked in (COLLADA files place meshes in a node hierarchy).
  importer.SetPropertyInteger(AI_CONFIG_PP_RVC_FLAGS, aiComponent_NORMALS);
  const unsigned flags = aiProcess_Triangulate | aiProcess_RemoveComponent | aiProcess_JoinIdenticalVertices |
                         aiProcess_GenSmoothNormals | aiProcess_PreTransformVertices | aiProcess_SortByPType;
  const aiScene* scene = importer.ReadFile(path.string(), flags);
  if (scene == nullptr) detail::throw_error(where + ": " + importer.GetErrorString());

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
      detail::throw_error(where + ": more vertices than 32-bit indices can address");
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
      for (unsigned i = 0; i < 3; ++i) facets.push_back(base + static_cast<std::int32_t>(face.mIndices[i]));
    }
  }
  if (facets.empty()) detail::throw_error(where + ": no triangles");
  if (!all_uv) uv.clear();  // texture coordinates only when every vertex has them

  geometry.set_kind(GeometryKind::Mesh);
  geometry.set_vertices(vertices);
  geometry.set_normals(normals);
  geometry.set_facets(facets);
  geometry.set_texture_coordinates(uv);
}

}  // namespace vsd::scene
