#include "tamp/render/render.h"

#include <cairo.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>

namespace tamp::render {
namespace {

namespace fs = std::filesystem;

world::World sampleWorld() {
  world::World w("sample");
  world::Object wall;
  wall.id = "wall";
  wall.shape = world::Shape::box(4.0, 0.2, 1.0);
  wall.pose.translation() = Eigen::Vector3d(2.0, 3.0, 0.5);
  EXPECT_TRUE(w.addObject(wall));
  world::Object box;
  box.id = "box";
  box.kind = world::ObjectKind::kMovable;
  box.mass = 3.0;
  box.shape = world::Shape::box(0.5, 0.5, 0.5);
  box.pose.translation() = Eigen::Vector3d(1.0, 1.0, 0.25);
  EXPECT_TRUE(w.addObject(box));
  world::Object ghost = box;
  ghost.id = "ghost";
  ghost.hidden = true;
  ghost.pose.translation() = Eigen::Vector3d(3.0, 1.0, 0.25);
  EXPECT_TRUE(w.addObject(ghost));
  world::Region floor;
  floor.id = "patch";
  floor.polygon = {{0, 0}, {4, 0}, {4, 2}, {0, 2}};
  EXPECT_TRUE(w.addRegion(floor));
  EXPECT_TRUE(w.addLocation(world::Location{"start", "", Pose2D{0.5, 2.0, 0.0}}));
  return w;
}

struct Pixel {
  unsigned char r, g, b;
};

// Reads back a PNG and samples pixels at world points (the same mapping as the renderer).
class Image {
 public:
  explicit Image(const fs::path& file) : s_(cairo_image_surface_create_from_png(file.c_str())) {}
  ~Image() { cairo_surface_destroy(s_); }
  bool ok() const { return cairo_surface_status(s_) == CAIRO_STATUS_SUCCESS; }
  int width() const { return cairo_image_surface_get_width(s_); }
  int height() const { return cairo_image_surface_get_height(s_); }
  Pixel at(int x, int y) const {
    cairo_surface_flush(s_);
    const unsigned char* d =
        cairo_image_surface_get_data(s_) + y * cairo_image_surface_get_stride(s_) + 4 * x;
    return Pixel{d[2], d[1], d[0]};  // ARGB32 little-endian: B G R A
  }

 private:
  cairo_surface_t* s_;
};

TEST(RenderTest, PngShowsObjectsInTheirStyles) {
  Drawing d;
  d.world = sampleWorld();
  d.title = "sample";
  Footprint robot;
  robot.polygon = {{-0.3, -0.25}, {0.3, -0.25}, {0.3, 0.25}, {-0.3, 0.25}};
  robot.pose = Pose2D{0.5, 2.0, 0.0};
  d.robots.push_back(robot);
  PathOverlay path;
  path.poses = {{0.5, 2.0, 0}, {2.0, 2.2, 0}, {3.5, 2.0, 0}};
  path.label = "plan";
  d.paths.push_back(path);
  RenderOptions o;
  o.pixels_per_metre = 50;
  o.margin_m = 0.5;
  o.show_labels = false;  // sample pure colours
  const fs::path file = fs::temp_directory_path() / "tamp_render_test.png";
  ASSERT_TRUE(renderPng(d, file, o));
  Image img(file);
  ASSERT_TRUE(img.ok());
  // View: x in [-0.5, 4.5] (bounds incl. the robot footprint at x = 0.2), y in [-0.5, 3.6].
  const Aabb b = d.world.bounds();
  const double x0 = std::min(b.min.x(), 0.2) - 0.5, y1 = b.max.y() + 0.5;
  auto pix = [&](double x, double y) {
    return img.at(static_cast<int>((x - x0) * 50), static_cast<int>((y1 - y) * 50));
  };
  EXPECT_EQ(img.width(), static_cast<int>(std::ceil((b.max.x() - x0 + 0.5) * 50)));
  const Pixel wall = pix(2.0, 3.0), box = pix(1.0, 1.0), ghost = pix(3.0, 1.0), bg = pix(4.3, 3.5);
  EXPECT_LT(wall.r, 100);  // dark grey
  EXPECT_NEAR(wall.r, wall.b, 10);
  EXPECT_GT(box.r, 200);  // orange
  EXPECT_LT(box.b, 100);
  EXPECT_GT(ghost.r, 200);  // hidden: faint red tint, not orange
  EXPECT_GT(ghost.b, 150);
  EXPECT_EQ(bg.r, 255);  // white background
  // Hiding the hidden object removes its tint.
  o.show_hidden = false;
  ASSERT_TRUE(renderPng(d, file, o));
  Image img2(file);
  const Pixel ghost2 =
      img2.at(static_cast<int>((3.0 - x0) * 50), static_cast<int>((y1 - 1.0) * 50));
  EXPECT_GT(ghost2.g, ghost.g);
}

TEST(RenderTest, SvgIsWritten) {
  Drawing d;
  d.world = sampleWorld();
  const fs::path file = fs::temp_directory_path() / "tamp_render_test.svg";
  ASSERT_TRUE(render(d, file));
  std::ifstream in(file);
  std::stringstream ss;
  ss << in.rdbuf();
  EXPECT_NE(ss.str().find("<svg"), std::string::npos);
  EXPECT_GT(ss.str().size(), 1000u);
}

TEST(RenderTest, Errors) {
  Drawing empty;
  const Status s = renderPng(empty, fs::temp_directory_path() / "x.png");
  ASSERT_FALSE(s);
  EXPECT_EQ(s.error().message, "nothing to draw (empty view)");
  Drawing d;
  d.world = sampleWorld();
  EXPECT_EQ(render(d, "out.jpg").error().message,
            "unknown picture format '.jpg' (expected .png or .svg)");
  const Status io = renderPng(d, "/nonexistent/dir/x.png");
  ASSERT_FALSE(io);
  EXPECT_EQ(io.error().code, ErrorCode::kIo);
  RenderOptions bad;
  bad.pixels_per_metre = 0;
  EXPECT_EQ(renderPng(d, "x.png", bad).error().message,
            "render options: pixels_per_metre must be positive");
  EXPECT_EQ(Rgba::fromHex("#ff8000")->g, 128 / 255.0);
  EXPECT_FALSE(Rgba::fromHex("ff8000").has_value());
  EXPECT_FALSE(Rgba::fromHex("#ff80zz").has_value());
}

TEST(RenderTest, OutlineOfRotatedAndTiltedObjects) {
  world::Object o;
  o.shape = world::Shape::box(2.0, 1.0, 0.5);
  o.pose = Pose2D{1, 1, M_PI / 2}.toIsometry(0.25);
  const auto poly = objectOutline(o);
  ASSERT_EQ(poly.size(), 4u);
  EXPECT_NEAR(std::abs(world::signedArea(poly)), 2.0, 1e-12);
  EXPECT_NEAR(poly[0].x(), 1.5, 1e-12);  // (-1, -0.5) rotated by 90 degrees -> (0.5, -1)
  EXPECT_NEAR(poly[0].y(), 0.0, 1e-12);
  o.pose.linear() = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitX()).toRotationMatrix();
  const auto tilted = objectOutline(o);  // lying on its side: the bounding box
  EXPECT_NEAR(std::abs(world::signedArea(tilted)), 2.0 * 0.5, 1e-12);
}

// Cairo and fontconfig keep font caches for the life of the process; release them at the end so
// that LeakSanitizer (asan preset) reports only real leaks.
class FontCacheRelease : public ::testing::Environment {
 public:
  void TearDown() override { releaseFontCaches(); }
};
const auto* const kFontCacheRelease = ::testing::AddGlobalTestEnvironment(new FontCacheRelease);

}  // namespace
}  // namespace tamp::render
