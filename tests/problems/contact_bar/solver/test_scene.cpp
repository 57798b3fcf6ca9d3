// Scene keys of the contact bar: the committed scenes load, bad values name their key.
#include <gtest/gtest.h>

#include "core/errors.hpp"
#include "problems/contact_bar/solver/scene.hpp"

namespace backbone::contact_bar {
namespace {

core::Scene load(const std::string& file, const std::vector<std::string>& args = {}) {
  po::options_description driver;
  return core::read_scene(
      scene_keys(),
      file.empty() ? "" : std::string(BACKBONE_SOURCE_DIR) + "/problems/contact_bar/scenes/" + file,
      args, driver);
}

TEST(ContactBarScene, PaperSceneIsModeOne) {
  const auto scene = load("paper.ini");
  const auto s = setup_from_scene(scene);
  EXPECT_EQ(s.left.type, bar::EndType::fixed);
  EXPECT_EQ(s.right.type, bar::EndType::contact);
  EXPECT_DOUBLE_EQ(s.right.gap, 1e-3);
  EXPECT_DOUBLE_EQ(s.u0(0.5), -0.005);
  EXPECT_DOUBLE_EQ(s.v0(0.5), 0.0);
  const auto o = simulation_from_scene(scene, 2);
  EXPECT_DOUBLE_EQ(o.t_end, 6.2);
  EXPECT_DOUBLE_EQ(o.dt, 0.01);
  EXPECT_EQ(o.elements, 100);
}

TEST(ContactBarScene, BouncingBarScene) {
  const auto s = setup_from_scene(load("bouncing_bar.ini"));
  EXPECT_DOUBLE_EQ(s.material.wave_speed(), 30.0);
  EXPECT_EQ(s.left.type, bar::EndType::free);
  EXPECT_DOUBLE_EQ(s.body_force, 10.0);
}

TEST(ContactBarScene, CommandLineWinsAndBadValuesNameTheKey) {
  EXPECT_DOUBLE_EQ(setup_from_scene(load("paper.ini", {"--gap", "0.5"})).right.gap, 0.5);
  auto key_of = [](const std::vector<std::string>& args) {
    try {
      const auto scene = load("paper.ini", args);
      setup_from_scene(scene);
      simulation_from_scene(scene, 1);
      contact_method_from_scene(scene);
    } catch (const core::InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(key_of({"--gap=-1"}).rfind("gap:", 0), 0u) << key_of({"--gap=-1"});
  EXPECT_EQ(key_of({"--length", "0"}).rfind("length:", 0), 0u);
  EXPECT_EQ(key_of({"--density", "nan"}).rfind("density:", 0), 0u);
  EXPECT_EQ(key_of({"--dt", "0"}).rfind("dt:", 0), 0u);
  EXPECT_EQ(key_of({"--contact", "magic"}).rfind("contact:", 0), 0u);
  EXPECT_EQ(key_of({"--u0", "0:0 2:1"}).rfind("u0:", 0), 0u);
  EXPECT_EQ(key_of({"--u0", "0:0 1:0.5"}).rfind("u0:", 0), 0u);  // penetrates the wall
  EXPECT_EQ(key_of({"--probes", "0.5 x"}).rfind("probes:", 0), 0u);
  EXPECT_EQ(key_of({"--elements", "0"}).rfind("elements:", 0), 0u);
  EXPECT_EQ(key_of({"--elements", "30000000000"}).rfind("elements:", 0), 0u);
  EXPECT_EQ(key_of({"--u0", "0:0 1:nan"}).rfind("u0:", 0), 0u);
  EXPECT_NE(key_of({"--no_such_key", "1"}).find("no_such_key"), std::string::npos);
}

TEST(ContactBarScene, KnotsParse) {
  const auto f = parse_knots("u0", "0:1 0.5:2 1:0", 1.0);
  EXPECT_DOUBLE_EQ(f(0.25), 1.5);
  EXPECT_THROW(parse_knots("u0", "0:1 0.5", 1.0), core::InputError);
  EXPECT_THROW(parse_knots("u0", "0.5:1 0.25:2", 1.0), core::InputError);
  EXPECT_DOUBLE_EQ(parse_knots("v0", "", 2.0)(1.0), 0.0);
}

}  // namespace
}  // namespace backbone::contact_bar
