#include "mrgi/json_reader.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "image/file_io.h"

namespace mrgi {
namespace {

// Numbers end up in 32-bit floats (GPU data, images): one finite as a double but not as a float
// (1e39) would become inf there.
constexpr double kMaxFloat = 3.4028234663852886e38;
const char* const kFloatRule = "must fit a 32-bit float (|value| <= 3.4e38)";

// JSON lets an object repeat a key and nlohmann keeps the last one silently
// ("depth_scale": -1, "depth_scale": 5000 would pass the range check): the parser callback
// records the first repeated key, with the key of the object holding it.
struct DuplicateKeys {
  std::vector<std::vector<std::string>> keys;  // per open object (arrays push an empty frame)
  std::vector<std::string> owner;               // the key each open container was under
  std::string last_key, found, found_in;
  bool operator()(int, nlohmann::json::parse_event_t event, nlohmann::json& parsed) {
    using E = nlohmann::json::parse_event_t;
    switch (event) {
      case E::object_start:
      case E::array_start:
        // An element of an array is labelled after the array ("lights[]").
        owner.push_back(last_key.empty() && !owner.empty() ? owner.back() + "[]" : last_key);
        keys.emplace_back();
        last_key.clear();
        break;
      case E::object_end:
      case E::array_end:
        if (!keys.empty()) keys.pop_back();
        if (!owner.empty()) owner.pop_back();
        last_key.clear();
        break;
      case E::key: {
        last_key = parsed.get<std::string>();
        if (keys.empty()) break;
        auto& seen = keys.back();
        if (found.empty() && std::find(seen.begin(), seen.end(), last_key) != seen.end()) {
          found = last_key;
          found_in = owner.empty() || owner.back().empty() ? "the top-level object" : "'" + owner.back() + "'";
        }
        seen.push_back(last_key);
        break;
      }
      case E::value:
        break;
    }
    return true;
  }
};

const char* type_name(const nlohmann::json& v) {
  if (v.is_boolean()) return "a boolean";
  if (v.is_number()) return "a number";
  if (v.is_string()) return "a string";
  if (v.is_array()) return "an array";
  if (v.is_object()) return "an object";
  if (v.is_null()) return "null";
  return "an unknown JSON value";
}

// nlohmann reports a byte offset; people read lines and columns.
std::string line_and_column(const std::vector<uint8_t>& bytes, size_t byte) {
  size_t line = 1, column = 1;
  for (size_t i = 0; i + 1 < byte && i < bytes.size(); ++i) {
    if (bytes[i] == '\n') {
      ++line;
      column = 1;
    } else {
      ++column;
    }
  }
  return "line " + std::to_string(line) + ", column " + std::to_string(column);
}

}  // namespace

Expected<nlohmann::json> load_json_file(const std::string& path) {
  auto bytes = read_file_bytes(path);
  if (!bytes) return bytes.error();
  try {
    DuplicateKeys dup;
    nlohmann::json j = nlohmann::json::parse(
        bytes->begin(), bytes->end(),
        [&dup](int depth, nlohmann::json::parse_event_t event, nlohmann::json& parsed) {
          return dup(depth, event, parsed);
        });
    if (!dup.found.empty())
      return fail(ErrorKind::BadInput, path + ": key '" + dup.found + "' appears twice in " + dup.found_in +
                                           " (JSON would keep the last silently; each key once)");
    return j;
  } catch (const nlohmann::json::parse_error& e) {
    std::string what = e.what();
    // Drop nlohmann's "[json.exception.parse_error.101] parse error at line 1, column 2: " prefix
    // in favour of our own position.
    const size_t colon = what.find(": ");
    if (colon != std::string::npos) what = what.substr(colon + 2);
    return fail(ErrorKind::BadInput,
                path + ":" + line_and_column(*bytes, e.byte) + ": invalid JSON: " + what);
  } catch (const nlohmann::json::exception& e) {  // e.g. out_of_range 406: number overflow
    std::string what = e.what();
    const size_t bracket = what.find("] ");
    if (bracket != std::string::npos) what = what.substr(bracket + 2);
    return fail(ErrorKind::BadInput, path + ": invalid JSON: " + what);
  }
}

Expected<JsonObject> JsonObject::from(const nlohmann::json& value, std::string file, std::string path) {
  if (!value.is_object())
    return fail(ErrorKind::BadInput, file + ": " + (path.empty() ? "top level" : path) +
                                         ": must be an object, got " + type_name(value));
  return JsonObject(&value, std::move(file), std::move(path));
}

std::string JsonObject::path_of(std::string_view key) const {
  return path_.empty() ? std::string(key) : path_ + "." + std::string(key);
}

Error JsonObject::error(std::string_view key, const std::string& rule) const {
  return fail(ErrorKind::BadInput, file_ + ": " + path_of(key) + ": " + rule);
}

Status JsonObject::only_keys(std::initializer_list<std::string_view> allowed) const {
  for (const auto& item : json_->items()) {
    bool known = false;
    for (std::string_view a : allowed) known = known || item.key() == a;
    if (!known) {
      std::string list;
      for (std::string_view a : allowed) list += (list.empty() ? "" : ", ") + std::string(a);
      return error(item.key(), "unknown key (allowed here: " + list + ")");
    }
  }
  return ok_status();
}

Status JsonObject::require(std::string_view key) const {
  if (!has(key)) return error(key, "required key is missing");
  return ok_status();
}

Expected<double> JsonObject::number(std::string_view key, std::optional<double> fallback) const {
  if (!has(key)) {
    if (fallback) return *fallback;
    return error(key, "required key is missing");
  }
  const auto& v = (*json_)[std::string(key)];
  if (!v.is_number()) return error(key, std::string("must be a number, got ") + type_name(v));
  const double d = v.get<double>();
  if (!std::isfinite(d)) return error(key, "must be finite");
  if (std::abs(d) > kMaxFloat) return error(key, kFloatRule);
  return d;
}

Expected<int> JsonObject::integer(std::string_view key, std::optional<int> fallback) const {
  if (!has(key)) {
    if (fallback) return *fallback;
    return error(key, "required key is missing");
  }
  const auto& v = (*json_)[std::string(key)];
  if (!v.is_number_integer()) return error(key, std::string("must be an integer, got ") + type_name(v));
  const auto i = v.get<int64_t>();
  if (i < -2147483647 || i > 2147483647) return error(key, "integer out of range");
  return int(i);
}

Expected<bool> JsonObject::boolean(std::string_view key, std::optional<bool> fallback) const {
  if (!has(key)) {
    if (fallback) return *fallback;
    return error(key, "required key is missing");
  }
  const auto& v = (*json_)[std::string(key)];
  if (!v.is_boolean()) return error(key, std::string("must be true or false, got ") + type_name(v));
  return v.get<bool>();
}

Expected<std::string> JsonObject::string(std::string_view key, std::optional<std::string> fallback) const {
  if (!has(key)) {
    if (fallback) return *fallback;
    return error(key, "required key is missing");
  }
  const auto& v = (*json_)[std::string(key)];
  if (!v.is_string()) return error(key, std::string("must be a string, got ") + type_name(v));
  return v.get<std::string>();
}

Expected<std::vector<double>> JsonObject::numbers(std::string_view key, size_t count) const {
  const auto& v = (*json_)[std::string(key)];
  if (!v.is_array() || v.size() != count)
    return error(key, "must be an array of " + std::to_string(count) + " numbers, got " +
                          (v.is_array() ? "an array of " + std::to_string(v.size()) : type_name(v)));
  std::vector<double> out;
  for (size_t i = 0; i < count; ++i) {
    if (!v[i].is_number())
      return error(std::string(key) + "[" + std::to_string(i) + "]",
                   std::string("must be a number, got ") + type_name(v[i]));
    const double d = v[i].get<double>();
    if (!std::isfinite(d)) return error(std::string(key) + "[" + std::to_string(i) + "]", "must be finite");
    if (std::abs(d) > kMaxFloat) return error(std::string(key) + "[" + std::to_string(i) + "]", kFloatRule);
    out.push_back(d);
  }
  return out;
}

Expected<glm::dvec3> JsonObject::vec3(std::string_view key, std::optional<glm::dvec3> fallback) const {
  if (!has(key)) {
    if (fallback) return *fallback;
    return error(key, "required key is missing");
  }
  auto n = numbers(key, 3);
  if (!n) return n.error();
  return glm::dvec3((*n)[0], (*n)[1], (*n)[2]);
}

Expected<glm::dquat> JsonObject::quat_xyzw(std::string_view key, std::optional<glm::dquat> fallback) const {
  if (!has(key)) {
    if (fallback) return *fallback;
    return error(key, "required key is missing");
  }
  auto n = numbers(key, 4);
  if (!n) return n.error();
  const glm::dquat q((*n)[3], (*n)[0], (*n)[1], (*n)[2]);
  const double len = std::sqrt(glm::dot(q, q));
  if (std::abs(len - 1.0) > kUnitQuaternionTolerance) {
    std::ostringstream rule;
    rule << "quaternion [x, y, z, w] must have unit length (within " << kUnitQuaternionTolerance
         << "), got length " << len;
    return error(key, rule.str());
  }
  return q;
}

Expected<JsonObject> JsonObject::object(std::string_view key) const {
  if (!has(key)) return error(key, "required key is missing");
  return from((*json_)[std::string(key)], file_, path_of(key));
}

Expected<std::vector<JsonObject>> JsonObject::objects(std::string_view key) const {
  if (!has(key)) return error(key, "required key is missing");
  const auto& v = (*json_)[std::string(key)];
  if (!v.is_array()) return error(key, std::string("must be an array, got ") + type_name(v));
  std::vector<JsonObject> out;
  for (size_t i = 0; i < v.size(); ++i) {
    auto o = from(v[i], file_, path_of(key) + "[" + std::to_string(i) + "]");
    if (!o) return o.error();
    out.push_back(*o);
  }
  return out;
}

}  // namespace mrgi
