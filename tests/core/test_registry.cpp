#include <gtest/gtest.h>

#include "core/EmbeddedFiles.hpp"
#include "core/Errors.hpp"
#include "core/Registry.hpp"

namespace {
struct Shape {
  virtual ~Shape() = default;
  virtual double area() const = 0;
};
struct Square : Shape {
  explicit Square(double s) : side(s) {}
  double area() const override { return side * side; }
  double side;
};
using ShapeRegistry = rcfd::Registry<Shape, double>;
const bool squareRegistered = ShapeRegistry::add(
    "square", "a square of the given side", [](double s) { return std::make_unique<Square>(s); });
}  // namespace

TEST(Registry, CreatesRegisteredModelByName) {
  ASSERT_TRUE(squareRegistered);
  auto shape = ShapeRegistry::create("square", 3.0);
  EXPECT_DOUBLE_EQ(shape->area(), 9.0);
}

TEST(Registry, UnknownNameListsValidNames) {
  try {
    ShapeRegistry::create("circle", 1.0);
    FAIL() << "expected std::out_of_range";
  } catch (const std::out_of_range& e) {
    EXPECT_NE(std::string(e.what()).find("circle"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("square"), std::string::npos);
  }
}

TEST(Registry, RefusesDuplicateNames) {
  EXPECT_THROW(ShapeRegistry::add("square", "again", [](double s) { return std::make_unique<Square>(s); }),
               std::logic_error);
}

TEST(Registry, CreateAtRefusesAnUnknownNameAsAnInputErrorAtItsPointer) {
  EXPECT_DOUBLE_EQ(ShapeRegistry::createAt("scene", "/shape", "square", 2.0)->area(), 4.0);
  try {
    ShapeRegistry::createAt("scene", "/shape", "circle", 1.0);
    FAIL() << "expected rcfd::InputError";
  } catch (const rcfd::InputError& e) {
    ASSERT_EQ(e.violations().size(), 1u);
    EXPECT_EQ(e.violations()[0].pointer, "/shape");
    EXPECT_EQ(e.violations()[0].message, ShapeRegistry::unknownNameMessage("circle"));
  }
}

namespace {
enum class Colour { Red, Green };
constexpr std::array<rcfd::NamedValue<Colour>, 2> kColours{{{"red", Colour::Red, "warm"}, {"green", Colour::Green, "cool"}}};
}  // namespace

TEST(NamedValue, ParsesNamesAndRefusesWithTheRegistrysMessage) {
  EXPECT_EQ(rcfd::parseNamedValue(kColours, "green", "scene", "/colour"), Colour::Green);
  EXPECT_STREQ(rcfd::nameOf(kColours, Colour::Red), "red");
  EXPECT_EQ(rcfd::namesOf(kColours), (std::vector<std::string>{"green", "red"}));
  try {
    rcfd::parseNamedValue(kColours, "blue", "scene", "/colour");
    FAIL() << "expected rcfd::InputError";
  } catch (const rcfd::InputError& e) {
    ASSERT_EQ(e.violations().size(), 1u);
    EXPECT_EQ(e.violations()[0].pointer, "/colour");
    EXPECT_EQ(e.violations()[0].message, "unknown name \"blue\"; valid names are: green red");
  }
}

TEST(Errors, InputErrorListsEveryViolation) {
  rcfd::InputError e("scene.json", {{"/a", "bad"}, {"/b/0", "worse"}});
  const std::string text = e.what();
  EXPECT_NE(text.find("/a: bad"), std::string::npos);
  EXPECT_NE(text.find("/b/0: worse"), std::string::npos);
  EXPECT_EQ(e.violations().size(), 2u);
}
