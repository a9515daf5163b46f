#pragma once
// The readers of a JSON scene's sections, one file each: json_settings.cpp (camera, film,
// integrator), json_materials.cpp, json_shapes.cpp, json_lights.cpp; json_scene.cpp calls them in
// this order. Each reads its section into the public structs and hands them to the SceneBuilder,
// which checks the values (scene/validate.hpp).
#include <string>

#include "lucent/scene_builder.hpp"
#include "scene/json_reader.hpp"

namespace lucent::scene_detail {

void parse_camera(const JsonReader& r, const json& j, SceneBuilder& b);      // "/camera"
void parse_film(const JsonReader& r, const json& j, SceneBuilder& b);        // "/film"
void parse_integrator(const JsonReader& r, const json& j, SceneBuilder& b);  // "/integrator"
void parse_materials(const JsonReader& r, const json& j, SceneBuilder& b);   // "/materials"
void parse_shapes(const JsonReader& r, const json& j, SceneBuilder& b);      // "/shapes"
void parse_lights(const JsonReader& r, const json& j, SceneBuilder& b);      // "/lights"

/// One material, `j` at `ptr` ("/materials/<name>"): its type and parameters. Textures it names
/// are loaded through `b`; the material is checked when it is added.
Material parse_material(const JsonReader& r, const json& j, const std::string& ptr,
                        const std::string& name, SceneBuilder& b);

}  // namespace lucent::scene_detail
