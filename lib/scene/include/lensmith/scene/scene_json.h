// Reading lensmith's analytic scene format ("lensmith-scene", JSON, lengths in metres), documented
// key by key in docs/scene-format.md. Reading is strict: an unknown key, a wrong type, a missing
// required key or a value out of range is a FileError naming file:line:col, the key's path and
// what was expected.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

#include "lensmith/scene/scene.h"
#include "lensmith/scene/scene_error.h"

namespace lensmith {

// The format version this build reads (the newest).
inline constexpr int kSceneFormatVersion = 1;

// Parses a scene from `text`. `file_name` names it in messages; relative image-texture paths are
// resolved against `base_dir` (empty = the current directory). Image textures are read here
// (read_radiance_image); a picture that cannot be read is a FileError at its "file" key that
// quotes the reader's message. The result has passed Scene::validate().
Scene read_scene_json(std::string_view text, const std::string& file_name, const std::filesystem::path& base_dir = {});

// Reads the scene file at `path` (relative textures resolved against its folder). Throws IoError
// when the file cannot be opened, FileError when its contents are not a valid scene.
Scene load_scene(const std::filesystem::path& path);

}  // namespace lensmith
