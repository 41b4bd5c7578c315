// The Foxglove messages of an export: base64 against RFC 4648's vectors, a grid's rows flipped to run along +y with
// its corner at the terrain's lower-left, every field a schema requires present in the messages written.
#include "marsala/monitor/foxglove_json.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstring>
#include <string>

namespace marsala::monitor {
namespace {

using nlohmann::json;

TEST(Base64, MatchesRfc4648) {
  EXPECT_EQ(base64(""), "");
  EXPECT_EQ(base64("f"), "Zg==");
  EXPECT_EQ(base64("fo"), "Zm8=");
  EXPECT_EQ(base64("foo"), "Zm9v");
  EXPECT_EQ(base64("foob"), "Zm9vYg==");
  EXPECT_EQ(base64("fooba"), "Zm9vYmE=");
  EXPECT_EQ(base64("foobar"), "Zm9vYmFy");
}

/// Decodes standard base64 (the reverse written here, independently of the encoder).
std::string unbase64(const std::string& text) {
  const std::string digits = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  std::uint32_t bits = 0;
  int n = 0;
  for (char ch : text) {
    if (ch == '=') break;
    bits = (bits << 6) | static_cast<std::uint32_t>(digits.find(ch));
    n += 6;
    if (n >= 8) {
      n -= 8;
      out.push_back(static_cast<char>((bits >> n) & 0xFFu));
    }
  }
  return out;
}

/// Every required field of `schema` present in `value`, recursively (objects and arrays of objects).
void expect_conforms(const json& value, const json& schema, const std::string& where) {
  if (schema.value("type", "") == "object") {
    ASSERT_TRUE(value.is_object()) << where;
    for (const auto& name : schema["required"]) EXPECT_TRUE(value.contains(name.get<std::string>())) << where << "." << name;
    for (const auto& [name, sub] : schema["properties"].items())
      if (value.contains(name)) expect_conforms(value[name], sub, where + "." + name);
  } else if (schema.value("type", "") == "array" && schema.contains("items")) {
    ASSERT_TRUE(value.is_array()) << where;
    for (const auto& v : value) expect_conforms(v, schema["items"], where + "[]");
  }
}

TEST(GridMessage, RowsRunNorthwardsFromTheLowerLeftCorner) {
  Heightmap t(GridGeometry{2, 3, 10.0, 20.0, 0.5});
  for (int r = 0; r < 2; ++r)
    for (int c = 0; c < 3; ++c) t(r, c) = 10.0 * r + c + 0.25;
  const json g = json::parse(grid_message(t, 1500000000));
  EXPECT_EQ(g["timestamp"]["sec"], 1);
  EXPECT_EQ(g["timestamp"]["nsec"], 500000000);
  EXPECT_EQ(g["column_count"], 3);
  EXPECT_EQ(g["pose"]["position"]["x"], 10.0);
  EXPECT_EQ(g["pose"]["position"]["y"], 20.0);
  EXPECT_EQ(g["cell_size"]["x"], 0.5);
  const std::string data = unbase64(g["data"].get<std::string>());
  ASSERT_EQ(data.size(), 24u);
  float first = 0.0f;
  std::memcpy(&first, data.data(), 4);  // the grid's row 0 is the terrain's southmost row (row 1)
  EXPECT_EQ(first, 10.25f);
  float last = 0.0f;
  std::memcpy(&last, data.data() + 20, 4);
  EXPECT_EQ(last, 2.25f);
  expect_conforms(g, json::parse(grid_schema().text), "grid");
}

TEST(SceneUpdateMessage, CarriesEachRobotsPoseAndStateAndFitsItsSchema) {
  RobotPose r;
  r.id = 2;
  r.name = "husky-2";
  r.position = {1.5, -2.25};
  r.z_m = 0.75;
  r.heading_rad = 0.5;
  r.state = "advance";
  r.material_m3 = 0.1;
  const json u = json::parse(scene_update_message({r}, 7));
  ASSERT_EQ(u["entities"].size(), 1u);
  const json& e = u["entities"][0];
  EXPECT_EQ(e["id"], "agent-2");
  EXPECT_EQ(e["cylinders"][0]["pose"]["position"]["x"], 1.5);
  EXPECT_NEAR(e["cylinders"][0]["pose"]["orientation"]["z"].get<double>(), std::sin(0.25), 1e-15);
  json meta;
  for (const auto& kv : e["metadata"]) meta[kv["key"].get<std::string>()] = kv["value"];
  EXPECT_EQ(meta["y_m"], "-2.25");
  EXPECT_EQ(meta["material_m3"], "0.1");
  EXPECT_EQ(meta["state"], "advance");
  expect_conforms(u, json::parse(scene_update_schema().text), "scene");
}

TEST(LogMessage, FitsItsSchema) {
  const json l = json::parse(log_message(3000000000, LogLevel::kWarning, "agent-1", "rejected: off the grid"));
  EXPECT_EQ(l["level"], 3);
  EXPECT_EQ(l["timestamp"]["sec"], 3);
  expect_conforms(l, json::parse(log_schema().text), "log");
}

}  // namespace
}  // namespace marsala::monitor
