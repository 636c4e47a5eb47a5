/** @file
 *  @brief Forward declarations of vsd::scene, the 3D scene schema (nodes with frames, hulls, geometry,
 *  maps, materials, links and joints) and its URDF and mesh loaders.
 */
#pragma once

namespace vsd::scene {

class Node3D;
class Hull;
class Geometry;
class TextureMap;
class Material;
class Link;
class Joint;
class Scene;
class Module;
struct UrdfOptions;
struct SceneReport;

}  // namespace vsd::scene
