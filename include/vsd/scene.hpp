/** @file
 *  @brief vsd::scene: 3D simulation as database content — frames, hulls, geometry, maps, materials,
 *  links and joints, and the URDF and mesh loaders (link vsd::scene).
 */
#pragma once

#include "vsd/core.hpp"
#include "vsd/scene/fwd.hpp"
#include "vsd/scene/geometry.hpp"
#include "vsd/scene/hull.hpp"
#include "vsd/scene/joint.hpp"
#include "vsd/scene/link.hpp"
#include "vsd/scene/material.hpp"
#include "vsd/scene/mesh_loader.hpp"
#include "vsd/scene/module.hpp"
#include "vsd/scene/node3d.hpp"
#include "vsd/scene/scene.hpp"
#include "vsd/scene/spatial_view.hpp"
#include "vsd/scene/support.hpp"
#include "vsd/scene/texture_map.hpp"
#include "vsd/scene/urdf_loader.hpp"
