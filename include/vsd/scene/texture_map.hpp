/** @file
 *  @brief TextureMap: an image (by URL) and what it means for a surface (colour, normals, radar
 *  reflection, ...). Shared by many hulls (Hull::maps is a shared reference list).
 */
#pragma once

#include <cstdint>
#include <string>

#include "vsd/core/named_model_instance.hpp"
#include "vsd/scene/namespace.hpp"

namespace vsd::scene {

/// @brief What a map's texels mean.
enum class MapFunction : std::uint8_t {
  Color,            ///< albedo / base colour
  Normal,           ///< tangent-space normals
  Diffuse,          ///< diffuse reflectance
  Specular,         ///< specular reflectance
  Bump,             ///< height
  Emissive,         ///< emitted light
  RadarReflection,  ///< radar cross-section per texel (sensor simulation)
  LidarReflection   ///< lidar reflectivity per texel (sensor simulation)
};
VSD_ENUM(MapFunction, Color, Normal, Diffuse, Specular, Bump, Emissive, RadarReflection, LidarReflection)

class TextureMap : public vsd::NamedModelInstance {
  VSD_INSTANCE(TextureMap, vsd::NamedModelInstance)
  /// The image, as written in the description (a file path, "package://..." or any URL).
  VSD_PROPERTY(std::string, url, "")
  VSD_PROPERTY(MapFunction, function, MapFunction::Color)
};

}  // namespace vsd::scene
