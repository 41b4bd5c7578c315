#include "marsala/monitor/foxglove_json.hpp"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstring>
#include <initializer_list>
#include <utility>

namespace marsala::monitor {
namespace {

using nlohmann::json;

// JSON Schema building blocks: every property listed is required, as the export always writes it.
json object_of(std::initializer_list<std::pair<const char*, json>> properties) {
  json o = {{"type", "object"}, {"properties", json::object()}, {"required", json::array()}};
  for (const auto& [name, schema] : properties) {
    o["properties"][name] = schema;
    o["required"].push_back(name);
  }
  return o;
}
json typed(const char* type) { return {{"type", type}}; }
json array_of(json items) { return {{"type", "array"}, {"items", std::move(items)}}; }

json time_schema() { return object_of({{"sec", typed("integer")}, {"nsec", typed("integer")}}); }
json vector3_schema() { return object_of({{"x", typed("number")}, {"y", typed("number")}, {"z", typed("number")}}); }
json pose_schema() {
  return object_of({{"position", vector3_schema()},
                    {"orientation", object_of({{"x", typed("number")},
                                               {"y", typed("number")},
                                               {"z", typed("number")},
                                               {"w", typed("number")}})}});
}
json color_schema() {
  return object_of({{"r", typed("number")}, {"g", typed("number")}, {"b", typed("number")}, {"a", typed("number")}});
}

std::string schema_text(const char* title, json schema) {
  schema["$schema"] = "https://json-schema.org/draft/2020-12/schema";
  schema["title"] = title;
  return schema.dump();
}

json time_of(std::uint64_t time_ns) {
  return {{"sec", time_ns / 1000000000u}, {"nsec", time_ns % 1000000000u}};
}

json pose_at(double x, double y, double z, double heading_rad) {
  return {{"position", {{"x", x}, {"y", y}, {"z", z}}},
          {"orientation", {{"x", 0.0}, {"y", 0.0}, {"z", std::sin(heading_rad / 2)}, {"w", std::cos(heading_rad / 2)}}}};
}

/// A robot's colour: the hue turns with its id, so neighbours differ.
json robot_colour(std::uint32_t id, bool dropped) {
  const double hue = std::fmod(static_cast<double>(id) * 0.618033988749895, 1.0) * 6.0;
  const double x = 1.0 - std::abs(std::fmod(hue, 2.0) - 1.0);
  const int sector = static_cast<int>(hue);
  const double rgb[6][3] = {{1, x, 0}, {x, 1, 0}, {0, 1, x}, {0, x, 1}, {x, 0, 1}, {1, 0, x}};
  return {{"r", rgb[sector][0]}, {"g", rgb[sector][1]}, {"b", rgb[sector][2]}, {"a", dropped ? 0.3 : 1.0}};
}

json robot_entity(const RobotPose& r, std::uint64_t time_ns) {
  const double body_height_m = 0.5 * r.body_diameter_m;
  const json colour = robot_colour(r.id, r.dropped);
  json metadata = json::array();
  const auto meta = [&metadata](const char* key, std::string value) {
    metadata.push_back({{"key", key}, {"value", std::move(value)}});
  };
  meta("agent_id", fmt::format("{}", r.id));
  meta("name", r.name);
  meta("x_m", fmt::format("{}", r.position.x));
  meta("y_m", fmt::format("{}", r.position.y));
  meta("z_m", fmt::format("{}", r.z_m));
  meta("heading_rad", fmt::format("{}", r.heading_rad));
  meta("state", r.state);
  meta("material_m3", fmt::format("{}", r.material_m3));
  meta("deposited_m3", fmt::format("{}", r.deposited_m3));
  meta("dropped", r.dropped ? "true" : "false");
  const json body = {{"pose", pose_at(r.position.x, r.position.y, r.z_m + body_height_m / 2, r.heading_rad)},
                     {"size", {{"x", r.body_diameter_m}, {"y", r.body_diameter_m}, {"z", body_height_m}}},
                     {"bottom_scale", 1.0},
                     {"top_scale", 1.0},
                     {"color", colour}};
  const json arrow = {{"pose", pose_at(r.position.x, r.position.y, r.z_m + body_height_m, r.heading_rad)},
                      {"shaft_length", 0.5 * r.body_diameter_m},
                      {"shaft_diameter", 0.1 * r.body_diameter_m},
                      {"head_length", 0.25 * r.body_diameter_m},
                      {"head_diameter", 0.2 * r.body_diameter_m},
                      {"color", colour}};
  const json label = {{"pose", pose_at(r.position.x, r.position.y, r.z_m + 2 * body_height_m, 0.0)},
                      {"billboard", true},
                      {"font_size", 14.0},
                      {"scale_invariant", true},
                      {"color", {{"r", 1.0}, {"g", 1.0}, {"b", 1.0}, {"a", 1.0}}},
                      {"text", fmt::format("{} {}", r.id, r.state)}};
  return {{"timestamp", time_of(time_ns)},  {"frame_id", kWorldFrame},   {"id", fmt::format("agent-{}", r.id)},
          {"lifetime", time_of(0)},          {"frame_locked", false},     {"metadata", metadata},
          {"arrows", json::array({arrow})},  {"cubes", json::array()},    {"spheres", json::array()},
          {"cylinders", json::array({body})}, {"lines", json::array()},   {"triangles", json::array()},
          {"texts", json::array({label})},   {"models", json::array()}};
}

}  // namespace

JsonSchema grid_schema() {
  const json field = object_of({{"name", typed("string")}, {"offset", typed("integer")}, {"type", typed("integer")}});
  json data = typed("string");
  data["contentEncoding"] = "base64";
  return {"foxglove.Grid", schema_text("foxglove.Grid", object_of({{"timestamp", time_schema()},
                                                                   {"frame_id", typed("string")},
                                                                   {"pose", pose_schema()},
                                                                   {"column_count", typed("integer")},
                                                                   {"cell_size", object_of({{"x", typed("number")},
                                                                                            {"y", typed("number")}})},
                                                                   {"row_stride", typed("integer")},
                                                                   {"cell_stride", typed("integer")},
                                                                   {"fields", array_of(field)},
                                                                   {"data", data}}))};
}

JsonSchema scene_update_schema() {
  const json cylinder = object_of({{"pose", pose_schema()},
                                   {"size", vector3_schema()},
                                   {"bottom_scale", typed("number")},
                                   {"top_scale", typed("number")},
                                   {"color", color_schema()}});
  const json arrow = object_of({{"pose", pose_schema()},
                                {"shaft_length", typed("number")},
                                {"shaft_diameter", typed("number")},
                                {"head_length", typed("number")},
                                {"head_diameter", typed("number")},
                                {"color", color_schema()}});
  const json text = object_of({{"pose", pose_schema()},
                               {"billboard", typed("boolean")},
                               {"font_size", typed("number")},
                               {"scale_invariant", typed("boolean")},
                               {"color", color_schema()},
                               {"text", typed("string")}});
  const json entity = object_of({{"timestamp", time_schema()},
                                 {"frame_id", typed("string")},
                                 {"id", typed("string")},
                                 {"lifetime", time_schema()},
                                 {"frame_locked", typed("boolean")},
                                 {"metadata", array_of(object_of({{"key", typed("string")}, {"value", typed("string")}}))},
                                 {"arrows", array_of(arrow)},
                                 {"cubes", typed("array")},
                                 {"spheres", typed("array")},
                                 {"cylinders", array_of(cylinder)},
                                 {"lines", typed("array")},
                                 {"triangles", typed("array")},
                                 {"texts", array_of(text)},
                                 {"models", typed("array")}});
  const json deletion = object_of({{"timestamp", time_schema()}, {"type", typed("integer")}, {"id", typed("string")}});
  return {"foxglove.SceneUpdate",
          schema_text("foxglove.SceneUpdate", object_of({{"deletions", array_of(deletion)}, {"entities", array_of(entity)}}))};
}

JsonSchema log_schema() {
  return {"foxglove.Log", schema_text("foxglove.Log", object_of({{"timestamp", time_schema()},
                                                                 {"level", typed("integer")},
                                                                 {"message", typed("string")},
                                                                 {"name", typed("string")},
                                                                 {"file", typed("string")},
                                                                 {"line", typed("integer")}}))};
}

std::string grid_message(const Heightmap& terrain, std::uint64_t time_ns) {
  const int rows = terrain.rows();
  const int cols = terrain.cols();
  std::string data(static_cast<std::size_t>(terrain.size()) * 4, '\0');
  std::size_t at = 0;
  for (int i = 0; i < rows; ++i)
    for (int c = 0; c < cols; ++c, at += 4) {
      const auto h = static_cast<float>(terrain(rows - 1 - i, c));
      std::uint32_t bits = 0;
      std::memcpy(&bits, &h, 4);
      for (int b = 0; b < 4; ++b) data[at + b] = static_cast<char>((bits >> (8 * b)) & 0xFFu);  // little-endian
    }
  const GridGeometry& g = terrain.geometry();
  constexpr int kFloat32 = 7;  // foxglove.NumericType FLOAT32
  const json message = {{"timestamp", time_of(time_ns)},
                        {"frame_id", kWorldFrame},
                        {"pose", pose_at(g.xll_m, g.yll_m, 0.0, 0.0)},
                        {"column_count", cols},
                        {"cell_size", {{"x", g.cell_size_m}, {"y", g.cell_size_m}}},
                        {"row_stride", cols * 4},
                        {"cell_stride", 4},
                        {"fields", json::array({{{"name", "height"}, {"offset", 0}, {"type", kFloat32}}})},
                        {"data", base64(data)}};
  return message.dump();
}

std::string scene_update_message(const std::vector<RobotPose>& robots, std::uint64_t time_ns) {
  json entities = json::array();
  for (const RobotPose& r : robots) entities.push_back(robot_entity(r, time_ns));
  return json{{"deletions", json::array()}, {"entities", std::move(entities)}}.dump();
}

std::string log_message(std::uint64_t time_ns, LogLevel level, const std::string& name, const std::string& text) {
  return json{{"timestamp", time_of(time_ns)}, {"level", static_cast<int>(level)}, {"message", text},
              {"name", name},                  {"file", ""},                         {"line", 0}}
      .dump();
}

std::string base64(const std::string& bytes) {
  static constexpr char kDigits[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  std::size_t i = 0;
  for (; i + 2 < bytes.size(); i += 3) {
    const std::uint32_t v = (static_cast<std::uint8_t>(bytes[i]) << 16) | (static_cast<std::uint8_t>(bytes[i + 1]) << 8) |
                            static_cast<std::uint8_t>(bytes[i + 2]);
    for (int k = 3; k >= 0; --k) out.push_back(kDigits[(v >> (6 * k)) & 0x3Fu]);
  }
  const std::size_t rest = bytes.size() - i;
  if (rest > 0) {
    std::uint32_t v = static_cast<std::uint8_t>(bytes[i]) << 16;
    if (rest == 2) v |= static_cast<std::uint8_t>(bytes[i + 1]) << 8;
    out.push_back(kDigits[(v >> 18) & 0x3Fu]);
    out.push_back(kDigits[(v >> 12) & 0x3Fu]);
    out.push_back(rest == 2 ? kDigits[(v >> 6) & 0x3Fu] : '=');
    out.push_back('=');
  }
  return out;
}

}  // namespace marsala::monitor
