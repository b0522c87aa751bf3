// The world file's `floor:` section (modules/floor): a PNG image placed by
// its corners, shapes drawn over it (circles, rectangles, gradients), the
// background; the paint layer drawn over it; the floor shown in recordings
// and snapshots; and each mistake a load error naming file:line:column.
#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "framework/floor_layer.h"
#include "modules/floor/floor.h"
#include "modules/paint/paint_layer.h"
#include "modules/paint/png_io.h"
#include "modules/rendering/video/recorder.h"
#include "swarm/record/reader.h"
#include "swarm/record/writer.h"
#include "tests/swarm/loader/world_dir_test.h"

namespace swarmsim {
namespace {

struct Rgb {
  int r, g, b;
  bool operator==(const Rgb&) const = default;
};
std::ostream& operator<<(std::ostream& os, const Rgb& c) {
  return os << "(" << c.r << ", " << c.g << ", " << c.b << ")";
}

// The floor layer's colour at (x, y) m (its background outside its area).
Rgb At(const FloorLayer& floor, double x, double y) {
  const FloorArea a = floor.floor_area();
  const int64_t p = FloorPixelAt(a, x, y);
  if (p < 0)
    return {static_cast<int>(a.background.x * 255 + 0.5),
            static_cast<int>(a.background.y * 255 + 0.5),
            static_cast<int>(a.background.z * 255 + 0.5)};
  const uint8_t* c = &floor.floor_rgb()[3 * p];
  return {c[0], c[1], c[2]};
}

void ExpectHas(const std::string& message, const std::vector<std::string>& fragments) {
  for (const std::string& fragment : fragments)
    EXPECT_NE(message.find(fragment), std::string::npos)
        << "expected '" << fragment << "' in: " << message;
}

class FloorSectionTest : public testing::WorldDirTest {
 protected:
  std::string ErrorOfWorld(const std::string& world_text) {
    try {
      Load(world_text);
    } catch (const Error& e) {
      return e.what();
    }
    return "(no error)";
  }
  // A 4 x 2 image: top row red, black, white, grey (128); bottom row
  // green, blue, yellow, magenta.
  void WriteQuadrants(const std::string& name) {
    const std::vector<uint8_t> rgb = {255, 0,   0, 0, 0, 0,   255, 255, 255, 128, 128, 128,
                                      0,   255, 0, 0, 0, 255, 255, 255, 0,   255, 0,   255};
    paint::WritePng(dir_ / name, 4, 2, rgb);
  }
  const std::string sim_ = "simulation: {physics: kinematic}\n";
};

TEST_F(FloorSectionTest, AnImageLiesWhereItsCornersSay) {
  WriteQuadrants("quads.png");
  // 4 x 2 pixels over x 0..2, y 0..1: each image pixel is 0.5 m square; the
  // floor (4 x 2 m, 0.05 m pixels) is grey 0.2 elsewhere.
  LoadedWorld w = Load(sim_ +
                       "floor:\n"
                       "  area: {min: [-1, -1], max: [3, 1]}\n"
                       "  resolution: 0.05\n"
                       "  background: 0.2\n"
                       "  image: {file: quads.png, min: [0, 0], max: [2, 1]}\n");
  const FloorLayer* floor = w.world->floor_layer();
  ASSERT_NE(floor, nullptr);
  EXPECT_EQ(floor->floor_area().width, 80);
  EXPECT_EQ(floor->floor_area().height, 40);
  // Row 0 of the image is its +y edge: y in [0.5, 1).
  EXPECT_EQ(At(*floor, 0.25, 0.75), (Rgb{255, 0, 0}));
  EXPECT_EQ(At(*floor, 0.75, 0.75), (Rgb{0, 0, 0}));
  EXPECT_EQ(At(*floor, 1.25, 0.75), (Rgb{255, 255, 255}));
  EXPECT_EQ(At(*floor, 1.75, 0.75), (Rgb{128, 128, 128}));
  EXPECT_EQ(At(*floor, 0.25, 0.25), (Rgb{0, 255, 0}));
  EXPECT_EQ(At(*floor, 1.75, 0.25), (Rgb{255, 0, 255}));
  // Edges to within a floor pixel: just inside and outside the image's corners.
  EXPECT_EQ(At(*floor, 0.49, 0.99), (Rgb{255, 0, 0}));
  EXPECT_EQ(At(*floor, 0.51, 0.99), (Rgb{0, 0, 0}));
  EXPECT_EQ(At(*floor, -0.03, 0.5), (Rgb{51, 51, 51}));  // the background, 0.2
  EXPECT_EQ(At(*floor, 2.03, 0.5), (Rgb{51, 51, 51}));
  EXPECT_EQ(At(*floor, 1.0, -0.03), (Rgb{51, 51, 51}));
  EXPECT_EQ(At(*floor, 5, 5), (Rgb{51, 51, 51}));  // outside the area
  // Only what differs from the background is marked (what a recording sends).
  EXPECT_TRUE(floor->floor_marked(20, 0 + 1));
  EXPECT_FALSE(floor->floor_marked(0, 0));
}

TEST_F(FloorSectionTest, AnImageIsScaledToItsCornersAndSetsTheDefaults) {
  WriteQuadrants("quads.png");
  // Stretched to 8 x 1 m (2 m by 0.5 m per image pixel); no area and no
  // arena: the image's corners are the area, at the default 1 cm.
  LoadedWorld w = Load(sim_ + "floor: {image: {file: quads.png, min: [-4, 0], max: [4, 1]}}\n");
  const FloorLayer* floor = w.world->floor_layer();
  ASSERT_NE(floor, nullptr);
  const FloorArea a = floor->floor_area();
  EXPECT_DOUBLE_EQ(a.resolution, 0.01);
  EXPECT_EQ(a.width, 800);
  EXPECT_EQ(a.height, 100);
  EXPECT_EQ(At(*floor, -3.9, 0.9), (Rgb{255, 0, 0}));
  EXPECT_EQ(At(*floor, -2.1, 0.6), (Rgb{255, 0, 0}));
  EXPECT_EQ(At(*floor, -1.9, 0.6), (Rgb{0, 0, 0}));
  EXPECT_EQ(At(*floor, 3.9, 0.1), (Rgb{255, 0, 255}));
  // Without corners, the image covers the area (here the arena's, 2 x 2 m).
  LoadedWorld c = Load(sim_ + "arena: {size: 2}\nfloor: {image: {file: quads.png}}\n");
  EXPECT_EQ(At(*c.world->floor_layer(), -0.9, 0.9), (Rgb{255, 0, 0}));
  EXPECT_EQ(At(*c.world->floor_layer(), 0.9, -0.9), (Rgb{255, 0, 255}));
  // An image finer than 1 cm sets the resolution: copied pixel for pixel.
  LoadedWorld f =
      Load(sim_ + "floor: {image: {file: quads.png, min: [0, 0], max: [0.02, 0.01]}}\n");
  EXPECT_DOUBLE_EQ(f.world->floor_layer()->floor_area().resolution, 0.005);
  EXPECT_EQ(f.world->floor_layer()->floor_area().width, 4);
  EXPECT_EQ(At(*f.world->floor_layer(), 0.0175, 0.0025), (Rgb{255, 0, 255}));
}

TEST_F(FloorSectionTest, ShapesAreDrawnInOrderOverTheImage) {
  WriteQuadrants("quads.png");
  LoadedWorld w = Load(sim_ +
                       "arena: {size: 2}\n"
                       "floor:\n"
                       "  resolution: 0.01\n"
                       "  image: {file: quads.png}\n"
                       "  shapes:\n"
                       "    - {type: rectangle, min: [-1, -1], max: [1, 0], color: [0, 0, 1]}\n"
                       "    - {type: circle, center: [0, 0], radius: 0.5, color: 0}\n"
                       "    - {type: circle, center: [0.5, 0.5], radius: 0.1, color: [1, 1, 0]}\n");
  const FloorLayer& floor = *w.world->floor_layer();
  // The nest: black inside the circle to within a pixel (0.01 m) of its edge.
  EXPECT_EQ(At(floor, 0, 0), (Rgb{0, 0, 0}));
  EXPECT_EQ(At(floor, 0.49, 0), (Rgb{0, 0, 0}));
  EXPECT_EQ(At(floor, 0.51, -0.01), (Rgb{0, 0, 255}));  // outside: the rectangle
  EXPECT_EQ(At(floor, 0, -0.49), (Rgb{0, 0, 0}));
  EXPECT_EQ(At(floor, 0, -0.51), (Rgb{0, 0, 255}));
  EXPECT_EQ(At(floor, 0.35, 0.35), (Rgb{0, 0, 0}));        // 0.495 m from the centre
  EXPECT_EQ(At(floor, 0.36, 0.36), (Rgb{255, 255, 255}));  // 0.509 m: the image (white)
  // The later circle over the first.
  EXPECT_EQ(At(floor, 0.45, 0.45), (Rgb{255, 255, 0}));
  // The image where no shape is.
  EXPECT_EQ(At(floor, -0.9, 0.9), (Rgb{255, 0, 0}));
}

TEST_F(FloorSectionTest, GradientsRunBetweenTheirEnds) {
  LoadedWorld w = Load(sim_ +
                       "arena: {size: 2}\n"
                       "floor:\n"
                       "  resolution: 0.01\n"
                       "  background: [1, 0, 0]\n"
                       "  shapes:\n"
                       "    - {type: linear_gradient, from: [-1, 0], to: [1, 0], from_color: 0,\n"
                       "       to_color: 1, min: [-1, -1], max: [1, 0]}\n"
                       "    - {type: radial_gradient, center: [0, 0.5], radius: 0.4,\n"
                       "       inner_color: [0, 0, 1], outer_color: [0, 0, 0]}\n");
  const FloorLayer& floor = *w.world->floor_layer();
  // Linear: grey = (x + 1) / 2 at the pixel's centre, within its bounds (y < 0).
  for (const double x : {-0.995, -0.505, 0.005, 0.495, 0.995}) {
    const int grey = static_cast<int>(std::lround((x + 1) / 2 * 255));
    EXPECT_EQ(At(floor, x, -0.5), (Rgb{grey, grey, grey})) << x;
  }
  EXPECT_EQ(At(floor, -0.5, 0.05), (Rgb{255, 0, 0}));  // above its bounds: background
  // Radial: blue at the centre, fading to black at 0.4 m; background beyond.
  EXPECT_EQ(At(floor, 0.005, 0.505),
            (Rgb{0, 0, static_cast<int>(std::lround((1 - std::sqrt(2) * 0.005 / 0.4) * 255))}));
  EXPECT_EQ(At(floor, 0.205, 0.505),
            (Rgb{0, 0, static_cast<int>(std::lround((1 - std::hypot(0.205, 0.005) / 0.4) * 255))}));
  EXPECT_EQ(At(floor, 0.45, 0.5), (Rgb{255, 0, 0}));
}

// A PNG whose header claims `width` x `height` pixels (no image data): what
// a reader sees before it decodes anything.
void WritePngHeader(const std::filesystem::path& path, uint32_t width, uint32_t height) {
  auto crc32 = [](const std::vector<uint8_t>& bytes) {
    uint32_t c = 0xFFFFFFFFu;
    for (uint8_t b : bytes) {
      c ^= b;
      for (int k = 0; k < 8; ++k) c = (c >> 1) ^ (0xEDB88320u & (0u - (c & 1u)));
    }
    return c ^ 0xFFFFFFFFu;
  };
  auto be32 = [](std::vector<uint8_t>* out, uint32_t v) {
    for (int s = 24; s >= 0; s -= 8) out->push_back(static_cast<uint8_t>(v >> s));
  };
  std::vector<uint8_t> file = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  std::vector<uint8_t> chunk = {'I', 'H', 'D', 'R'};
  be32(&chunk, width);
  be32(&chunk, height);
  chunk.insert(chunk.end(), {8, 2, 0, 0, 0});  // 8-bit RGB
  be32(&file, 13);
  file.insert(file.end(), chunk.begin(), chunk.end());
  be32(&file, crc32(chunk));
  // An empty IDAT (where a reader stops reading the header) and the end.
  for (const char* name : {"IDAT", "IEND"}) {
    const std::vector<uint8_t> empty(name, name + 4);
    be32(&file, 0);
    file.insert(file.end(), empty.begin(), empty.end());
    be32(&file, crc32(empty));
  }
  std::ofstream(path, std::ios::binary)
      .write(reinterpret_cast<const char*>(file.data()), static_cast<std::streamsize>(file.size()));
}

TEST_F(FloorSectionTest, BadFloorsNameTheirPlace) {
  const std::string arena = sim_ + "arena: {size: 2}\n";
  // A missing image, a file that is not a PNG, one over the limit.
  ExpectHas(ErrorOfWorld(arena + "floor:\n  image: {file: nowhere.png}\n"),
            {"world.yaml:4:17:", "floor image", "nowhere.png", "not found"});
  Write("notes.png", "these are notes, not a picture\n");
  ExpectHas(ErrorOfWorld(arena + "floor:\n  image: {file: notes.png}\n"),
            {"world.yaml:4:17:", "notes.png", "PNG"});
  WritePngHeader(dir_ / "huge.png", 10000, 7000);  // 70 megapixels
  ExpectHas(ErrorOfWorld(arena + "floor:\n  image: {file: huge.png}\n"),
            {"world.yaml:4:17:", "huge.png", "10000 x 7000", "64 megapixels"});
  // Shapes: a negative radius, an unknown type, a key of another type.
  ExpectHas(ErrorOfWorld(arena +
                         "floor:\n  shapes:\n    - {type: circle, center: [0, 0], radius: -0.3}\n"),
            {"world.yaml:5:46:", "radius", "non-negative"});
  ExpectHas(ErrorOfWorld(arena + "floor:\n  shapes:\n    - {type: circel, center: [0, 0]}\n"),
            {"world.yaml:5:14:", "did you mean 'circle'"});
  ExpectHas(
      ErrorOfWorld(arena + "floor:\n  shapes:\n    - {type: rectangle, min: [0, 0], max: [1, 1], "
                           "radius: 1}\n"),
      {"world.yaml:5:", "radius"});
  ExpectHas(ErrorOfWorld(arena +
                         "floor:\n  shapes:\n    - {type: rectangle, min: [1, 0], max: [0, 1]}\n"),
            {"world.yaml:5:", "max greater than min"});
  ExpectHas(ErrorOfWorld(arena + "floor:\n  background: [1, 2, 0]\n"),
            {"world.yaml:4:", "background"});
  // No area to draw on; a misspelt key; a raster over the limit.
  ExpectHas(ErrorOfWorld(sim_ + "floor: {background: 0}\n"), {"world.yaml:2:", "area"});
  ExpectHas(ErrorOfWorld(arena + "floor: {shape: []}\n"),
            {"world.yaml:3:", "did you mean 'shapes'"});
  ExpectHas(ErrorOfWorld(arena + "floor: {resolution: 0.0001}\n"), {"world.yaml:3:", "megapixels"});
  // With a floor, paint's background is the floor's.
  ExpectHas(ErrorOfWorld(arena + "floor: {background: 0}\npaint: {background: [1, 1, 1]}\n"),
            {"world.yaml:4:9:", "background"});
}

// A robot with a red paint nozzle, driven along y = 0.5 by the test.
const char kPainterModel[] =
    "model: painter\n"
    "objects:\n"
    "  type: dummy\n"
    "  children: [{name: pen, type: paint_nozzle, radius: 0.05, color: [1, 0, 0]}]\n";

TEST_F(FloorSectionTest, PaintIsDrawnOverTheFloor) {
  Write("painter.yaml", kPainterModel);
  LoadedWorld w = Load(sim_ +
                       "arena: {size: 2}\n"
                       "floor:\n"
                       "  resolution: 0.02\n"
                       "  background: 1\n"
                       "  shapes: [{type: circle, center: [0, 0], radius: 0.3, color: 0}]\n"
                       "models: [{model: painter.yaml, position: [-0.5, 0.5, 0]}]\n");
  // The paint layer took the floor's place, over its area and at its resolution.
  const FloorLayer* layer = w.world->floor_layer();
  ASSERT_NE(layer, nullptr);
  EXPECT_EQ(layer->floor_area().width, 100);
  EXPECT_DOUBLE_EQ(layer->floor_area().resolution, 0.02);
  EXPECT_EQ(At(*layer, 0, 0), (Rgb{0, 0, 0}));  // the nest, from the start
  w.world->Start();
  const ObjectId robot = w.world->scene().instances()[0].root;
  for (int i = 0; i <= 10; ++i) {
    w.world->scene().SetLocalPose(robot, {{-0.5 + 0.1 * i, 0.5, 0}, {}});
    w.world->Step();
  }
  w.world->Step();
  // The trail along y = 0.5 is red; the nest is still black; the bare floor white.
  EXPECT_EQ(At(*layer, 0, 0.5), (Rgb{255, 0, 0}));
  EXPECT_EQ(At(*layer, 0, 0), (Rgb{0, 0, 0}));
  EXPECT_EQ(At(*layer, 0.8, -0.8), (Rgb{255, 255, 255}));
  // Paint over the nest is paint: a trail across it.
  w.world->scene().SetLocalPose(robot, {{0, 0, 0}, {}});
  w.world->Step();
  EXPECT_EQ(At(*layer, 0, 0), (Rgb{255, 0, 0}));
  EXPECT_EQ(At(*layer, 0.2, 0), (Rgb{0, 0, 0}));
  // paint.png holds both.
  w.world->WriteOutputs(dir_);
  const paint::RgbImage png = paint::ReadPng(dir_ / "paint.png");
  ASSERT_EQ(png.width, 100);
  auto png_at = [&](double x, double y) {
    const size_t c = static_cast<size_t>((x + 1) / 0.02), r = static_cast<size_t>((1 - y) / 0.02);
    const uint8_t* p = &png.rgb[3 * (r * 100 + c)];
    return Rgb{p[0], p[1], p[2]};
  };
  EXPECT_EQ(png_at(0.2, 0.01), (Rgb{0, 0, 0}));
  EXPECT_EQ(png_at(-0.3, 0.5), (Rgb{255, 0, 0}));
  EXPECT_EQ(png_at(0.8, -0.8), (Rgb{255, 255, 255}));
}

TEST_F(FloorSectionTest, TheFloorIsRecordedForTheViewer) {
  LoadedWorld w =
      Load(sim_ +
           "arena: {size: 2}\n"
           "floor:\n"
           "  resolution: 0.1\n"
           "  background: [0, 0, 1]\n"
           "  shapes: [{type: rectangle, min: [0, 0], max: [1, 1], color: [1, 0, 0]}]\n");
  record::RecordSettings settings;
  settings.out_dir = dir_;
  record::RunRecorder* recorder = record::AddRecorder(w.world.get(), settings);
  w.world->Start();
  w.world->Step();
  recorder->Finish(1, "ok", "");
  record::RecordingPlayer player(dir_);
  ASSERT_TRUE(player.Next());
  const std::vector<uint8_t>& rgb = player.paint_rgb();
  ASSERT_EQ(rgb.size(), 20u * 20u * 3u);
  // The red square (x, y in 0..1: columns 10..19, rows 0..9), blue elsewhere.
  auto at = [&](int c, int r) {
    const uint8_t* p = &rgb[3 * (r * 20 + c)];
    return Rgb{p[0], p[1], p[2]};
  };
  EXPECT_EQ(at(15, 5), (Rgb{255, 0, 0}));
  EXPECT_EQ(at(5, 5), (Rgb{0, 0, 255}));
  EXPECT_EQ(at(15, 15), (Rgb{0, 0, 255}));
}

TEST_F(FloorSectionTest, SnapshotsShowTheFloor) {
  // A red left half and a blue right half; no robots, nothing else on the floor.
  LoadedWorld w =
      Load(sim_ +
           "arena: {size: 2, wall_height: 0.01}\n"
           "floor:\n"
           "  resolution: 0.02\n"
           "  shapes: [{type: rectangle, min: [-1, -1], max: [0, 1], color: [1, 0, 0]},\n"
           "           {type: rectangle, min: [0, -1], max: [1, 1], color: [0, 0, 1]}]\n");
  video::RecorderSettings settings;
  settings.out_dir = dir_;
  settings.snapshot_every = 1;
  settings.width = 160;
  settings.height = 120;
  w.world->AddModule("recorder", &settings);
  w.world->Start();
  w.world->Step();
  w.world->WriteOutputs(dir_);
  const paint::RgbImage image = paint::ReadPng(dir_ / "snapshots" / "step_000001.png");
  ASSERT_EQ(image.width, 160);
  // Reddish pixels lie left of bluish ones (the camera looks down, north up).
  int red = 0, blue = 0;
  double red_x = 0, blue_x = 0;
  for (int r = 0; r < image.height; ++r)
    for (int c = 0; c < image.width; ++c) {
      const uint8_t* p = &image.rgb[3 * (static_cast<size_t>(r) * image.width + c)];
      if (p[0] > 120 && p[1] < 60 && p[2] < 60) ++red, red_x += c;
      if (p[2] > 120 && p[0] < 60 && p[1] < 60) ++blue, blue_x += c;
    }
  EXPECT_GT(red, 1000);
  EXPECT_GT(blue, 1000);
  EXPECT_LT(red_x / std::max(red, 1), blue_x / std::max(blue, 1));
}

}  // namespace
}  // namespace swarmsim
