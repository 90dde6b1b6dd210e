// Strict reading of JSON settings files (scene.json, capture.json, perf manifests).
// Every getter checks type and range and names the file, the JSON path (e.g.
// `lights[1].inner_angle_deg`) and the rule broken. Unknown keys are refused by only_keys().
#pragma once
#include <initializer_list>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>
#include <nlohmann/json.hpp>

#include "mrgi/expected.h"

namespace mrgi {

// Reads and parses a JSON file. NotFound when absent; BadInput with line and column on a
// syntax error.
Expected<nlohmann::json> load_json_file(const std::string& path);

// Quaternions given in files must have unit length within this tolerance.
inline constexpr double kUnitQuaternionTolerance = 1e-3;

// A view of one JSON object at a known path inside a known file.
class JsonObject {
 public:
  // Fails unless `value` is an object.
  static Expected<JsonObject> from(const nlohmann::json& value, std::string file, std::string path);

  const std::string& file() const { return file_; }
  const std::string& path() const { return path_; }  // "" for the root object
  const nlohmann::json& json() const { return *json_; }

  // Refuses any key not in `allowed`.
  Status only_keys(std::initializer_list<std::string_view> allowed) const;
  // Refuses when the key is absent.
  Status require(std::string_view key) const;
  bool has(std::string_view key) const { return json_->contains(key); }

  // "KEY" prefixed by this object's path: "lights[1].inner_angle_deg".
  std::string path_of(std::string_view key) const;
  // BadInput "FILE: PATH.KEY: RULE".
  Error error(std::string_view key, const std::string& rule) const;

  // Each getter returns `fallback` when the key is absent and a fallback is given, else refuses
  // the missing key. Numbers must be finite.
  Expected<double> number(std::string_view key, std::optional<double> fallback = {}) const;
  Expected<int> integer(std::string_view key, std::optional<int> fallback = {}) const;
  Expected<bool> boolean(std::string_view key, std::optional<bool> fallback = {}) const;
  Expected<std::string> string(std::string_view key, std::optional<std::string> fallback = {}) const;
  Expected<glm::dvec3> vec3(std::string_view key, std::optional<glm::dvec3> fallback = {}) const;
  // [x, y, z, w] with |q| = 1 within kUnitQuaternionTolerance; returned in glm's (w, x, y, z).
  Expected<glm::dquat> quat_xyzw(std::string_view key, std::optional<glm::dquat> fallback = {}) const;
  Expected<JsonObject> object(std::string_view key) const;
  // An array of objects; each element's path is KEY[i].
  Expected<std::vector<JsonObject>> objects(std::string_view key) const;

 private:
  JsonObject(const nlohmann::json* json, std::string file, std::string path)
      : json_(json), file_(std::move(file)), path_(std::move(path)) {}
  Expected<std::vector<double>> numbers(std::string_view key, size_t count) const;

  const nlohmann::json* json_;  // owned by the caller, outlives this view
  std::string file_, path_;
};

// JSON writing helpers matching the readers above.
inline nlohmann::json to_json_array(const glm::dvec3& v) { return {v.x, v.y, v.z}; }
inline nlohmann::json to_json_xyzw(const glm::dquat& q) { return {q.x, q.y, q.z, q.w}; }

}  // namespace mrgi
