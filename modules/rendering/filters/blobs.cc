// Blob detection: the 8-connected parts of a mask, found on runs of set
// pixels (one union-find node per run, not per pixel), with their moments.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <vector>

#include "modules/rendering/filters/element.h"

namespace swarmsim::filters {
namespace {

// A run of set pixels in one row; `parent` links runs of one blob.
struct Span {
  int x0, x1, y;  // x0..x1 inclusive
  int parent;
};

int Find(std::vector<Span>& spans, int i) {
  while (spans[i].parent != i) {
    spans[i].parent = spans[spans[i].parent].parent;  // path halving
    i = spans[i].parent;
  }
  return i;
}

// The earlier run becomes the root, so a blob's root is its first run in
// raster order whatever the order of the unions.
void Union(std::vector<Span>& spans, int a, int b) {
  a = Find(spans, a);
  b = Find(spans, b);
  if (a < b) spans[b].parent = a;
  if (b < a) spans[a].parent = b;
}

// Sums over one blob's pixels (pixel indices; exact in integers).
struct Moments {
  int64_t n = 0, sx = 0, sy = 0, sxx = 0, syy = 0, sxy = 0;
  int64_t r = 0, g = 0, b = 0;
  int min_x = 0, min_y = 0, max_x = 0, max_y = 0;
  int first = 0;  // creation order, for ties
};

}  // namespace

void DetectBlobs(FilterRun* run, int min_pixels, int max_blobs) {
  FilterOutput* out = run->out;
  const WorkImage& mask = run->work;
  const int width = mask.width, height = mask.height;
  const Image& source = *run->source;
  const bool same_size = source.width == width && source.height == height;
  // Runs, row by row, joined to the runs of the row above that touch them
  // (diagonals included).
  std::vector<Span> spans;
  spans.reserve(static_cast<size_t>(height) * 4);
  size_t above_begin = 0, above_end = 0;
  for (int y = 0; y < height; ++y) {
    const uint8_t* row = mask.pixels.data() + static_cast<size_t>(y) * width;
    const size_t row_begin = spans.size();
    size_t p = above_begin;
    for (int x = 0; x < width;) {
      // Eight clear pixels at a time (masks are mostly clear).
      uint64_t eight;
      if (x + 8 <= width && (std::memcpy(&eight, row + x, 8), eight == 0)) {
        x += 8;
        continue;
      }
      if (row[x] == 0) {
        ++x;
        continue;
      }
      const int x0 = x;
      while (x < width && row[x] != 0) ++x;
      const int self = static_cast<int>(spans.size());
      spans.push_back({x0, x - 1, y, self});
      while (p < above_end && spans[p].x1 < x0 - 1) ++p;
      for (size_t q = p; q < above_end && spans[q].x0 <= x; ++q)
        Union(spans, static_cast<int>(q), self);
    }
    above_begin = row_begin;
    above_end = spans.size();
  }
  // Blobs in order of their first run; each run's pixels into its blob.
  std::vector<int> blob_of(spans.size());
  std::vector<Moments> moments;
  for (size_t i = 0; i < spans.size(); ++i) {
    const int root = Find(spans, static_cast<int>(i));
    if (root == static_cast<int>(i)) {
      blob_of[i] = static_cast<int>(moments.size());
      Moments m;
      m.min_x = spans[i].x0, m.max_x = spans[i].x1;
      m.min_y = m.max_y = spans[i].y;
      m.first = static_cast<int>(moments.size());
      moments.push_back(m);
    } else {
      blob_of[i] = blob_of[static_cast<size_t>(root)];
    }
    const Span& s = spans[i];
    Moments& m = moments[static_cast<size_t>(blob_of[i])];
    const int64_t n = s.x1 - s.x0 + 1, y = s.y;
    // Sums of x and x^2 over x0..x1 in closed form.
    const auto sum1 = [](int64_t k) { return k * (k + 1) / 2; };
    const auto sum2 = [](int64_t k) { return k * (k + 1) * (2 * k + 1) / 6; };
    const int64_t sx = sum1(s.x1) - sum1(s.x0 - 1);
    m.n += n;
    m.sx += sx;
    m.sy += n * y;
    m.sxx += sum2(s.x1) - sum2(s.x0 - 1);
    m.syy += n * y * y;
    m.sxy += sx * y;
    m.min_x = std::min(m.min_x, s.x0);
    m.max_x = std::max(m.max_x, s.x1);
    m.max_y = std::max(m.max_y, s.y);
    // The source's colour under the run (nearest pixel if the mask was resized).
    if (same_size) {
      const uint8_t* c = source.Pixel(s.x0, s.y);
      for (int64_t k = 0; k < n; ++k, c += 3) m.r += c[0], m.g += c[1], m.b += c[2];
    } else if (!source.rgb.empty()) {
      const int sy = static_cast<int>((2 * y + 1) * source.height / (2 * height));
      for (int x = s.x0; x <= s.x1; ++x) {
        const int sx_pixel = (2 * x + 1) * source.width / (2 * width);
        const uint8_t* c = source.Pixel(sx_pixel, sy);
        m.r += c[0], m.g += c[1], m.b += c[2];
      }
    }
  }
  // Largest first; equal sizes in raster order of their first pixel.
  std::vector<Moments*> order;
  for (Moments& m : moments)
    if (m.n >= min_pixels) order.push_back(&m);
  std::sort(order.begin(), order.end(), [](const Moments* a, const Moments* b) {
    return a->n != b->n ? a->n > b->n : a->first < b->first;
  });
  if (order.size() > static_cast<size_t>(max_blobs)) order.resize(static_cast<size_t>(max_blobs));

  out->blobs.clear();
  const double w = width, h = height, pixels = w * h;
  for (const Moments* m : order) {
    Blob blob;
    const double n = static_cast<double>(m->n);
    const double mx = static_cast<double>(m->sx) / n, my = static_cast<double>(m->sy) / n;
    blob.pixels = static_cast<int>(m->n);
    blob.colour = {static_cast<double>(m->r) / (255 * n), static_cast<double>(m->g) / (255 * n),
                   static_cast<double>(m->b) / (255 * n)};
    blob.x = mx + 0.5;
    blob.y = my + 0.5;
    blob.u = blob.x / w;
    blob.v = 1 - blob.y / h;
    blob.min_x = m->min_x, blob.min_y = m->min_y, blob.max_x = m->max_x, blob.max_y = m->max_y;
    // Principal axis from the central second moments (image y down, then
    // turned to y up).
    const double mu20 = static_cast<double>(m->sxx) / n - mx * mx;
    const double mu02 = static_cast<double>(m->syy) / n - my * my;
    const double mu11 = static_cast<double>(m->sxy) / n - mx * my;
    const double a = std::abs(mu11) < 1e-12 && std::abs(mu20 - mu02) < 1e-12
                         ? 0.0
                         : -0.5 * std::atan2(2 * mu11, mu20 - mu02);
    blob.orientation = a <= -M_PI / 2 ? a + M_PI : a;
    out->blobs.push_back(blob);
  }
  // The packet: count, values per blob, then per blob CoppeliaSim's six
  // (relative size, orientation, x, y, width, height) and colour and pixels.
  std::vector<double>& packet = run->NewPacket();
  constexpr int kValuesPerBlob = 10;
  packet.reserve(2 + kValuesPerBlob * out->blobs.size());
  packet.push_back(static_cast<double>(out->blobs.size()));
  packet.push_back(kValuesPerBlob);
  for (const Blob& b : out->blobs) {
    packet.insert(packet.end(),
                  {b.pixels / pixels, b.orientation, b.u, b.v, (b.max_x - b.min_x + 1) / w,
                   (b.max_y - b.min_y + 1) / h, b.colour[0], b.colour[1], b.colour[2],
                   static_cast<double>(b.pixels)});
  }
  if (!out->blobs.empty()) out->triggered = true;
}

}  // namespace swarmsim::filters
