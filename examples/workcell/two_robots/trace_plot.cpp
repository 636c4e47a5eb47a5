#include "trace_plot.hpp"

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>

#include "png_image.hpp"
#include "vsd/core/error.hpp"

namespace vsd_workcell {

void TracePlot::add(const TraceSample& s) {
  if (!samples_.empty()) {
    const TraceSample& last = samples_.back();
    const bool zone_changed = last.a_in_zone != s.a_in_zone || last.b_in_zone != s.b_in_zone;
    if (!zone_changed && s.t - last.t < interval_) return;
  }
  samples_.push_back(s);
  if (samples_.size() >= max_samples) {
    // A long run: keep every other sample and sample half as often from now on. The picture is 1,160
    // pixels wide; memory stays bounded however long the run.
    std::size_t k = 0;
    for (std::size_t i = 0; i < samples_.size(); i += 2) samples_[k++] = samples_[i];
    samples_.resize(k);
    interval_ *= 2;
  }
}

void TracePlot::write(const std::string& path) const {
  using vsd_example::Rgb;
  constexpr int width = 1200, left = 40, right = 20, plot_w = width - left - right;
  const Rgb white{255, 255, 255}, grid{220, 220, 220}, frame{90, 90, 90}, red{200, 30, 30}, blue{30, 60, 200},
      zone_shade{255, 240, 190}, black{0, 0, 0};
  struct Panel {
    int top, height;
    double lo, hi;  // m
  };
  const Panel py{20, 260, -1.6, 1.6}, px{300, 200, -1.4, 1.4};
  const int occ_top = 520, row = 30, height = occ_top + 2 * row + 30;
  vsd_example::Image img(width, height, white);
  const double t_end = samples_.empty() ? 1.0 : std::max(samples_.back().t, 1.0);
  auto x_of = [&](double t) { return left + t / t_end * plot_w; };
  auto y_of = [](const Panel& p, double v) { return p.top + (p.hi - v) / (p.hi - p.lo) * p.height; };
  // Shading and grid first, the curves over them.
  img.fill(left, static_cast<int>(y_of(px, 0.15)), left + plot_w, static_cast<int>(y_of(px, -0.15)), zone_shade);
  const double tick = t_end > 600 ? 60 : 10;
  for (double t = 0; t <= t_end; t += tick)
    for (int y0 : {py.top, px.top, occ_top}) {
      const int y1 = y0 == occ_top ? occ_top + 2 * row : y0 + (y0 == py.top ? py.height : px.height);
      img.line(x_of(t), y0, x_of(t), y1, grid);
    }
  for (double v : {-0.75, 0.0, 0.75}) img.line(left, y_of(py, v), left + plot_w, y_of(py, v), grid);
  for (const Panel& p : {py, px}) {
    img.line(left, p.top, left + plot_w, p.top, frame);
    img.line(left, p.top + p.height, left + plot_w, p.top + p.height, frame);
    img.line(left, p.top, left, p.top + p.height, frame);
    img.line(left + plot_w, p.top, left + plot_w, p.top + p.height, frame);
  }
  img.line(left, occ_top + row, left + plot_w, occ_top + row, grid);
  for (std::size_t i = 0; i < samples_.size(); ++i) {
    const TraceSample& s = samples_[i];
    if (i > 0) {
      const TraceSample& p = samples_[i - 1];
      img.line(x_of(p.t), y_of(py, p.a[1]), x_of(s.t), y_of(py, s.a[1]), red);
      img.line(x_of(p.t), y_of(py, p.b[1]), x_of(s.t), y_of(py, s.b[1]), blue);
      img.line(x_of(p.t), y_of(px, p.a[0]), x_of(s.t), y_of(px, s.a[0]), red);
      img.line(x_of(p.t), y_of(px, p.b[0]), x_of(s.t), y_of(px, s.b[0]), blue);
    }
    // Occupancy: from this sample to the next.
    const double t1 = i + 1 < samples_.size() ? samples_[i + 1].t : s.t;
    const int x0 = static_cast<int>(x_of(s.t)), x1 = std::max(x0, static_cast<int>(x_of(t1)));
    if (s.a_in_zone && s.b_in_zone)
      img.fill(x0, occ_top, x1, occ_top + 2 * row, black);
    else if (s.a_in_zone)
      img.fill(x0, occ_top + 3, x1, occ_top + row - 3, red);
    else if (s.b_in_zone)
      img.fill(x0, occ_top + row + 3, x1, occ_top + 2 * row - 3, blue);
  }
  vsd_example::write_png(path, img);
}

void check_writable(const std::string& path) {
  const std::string tmp = path + ".tmp";
  std::FILE* f = std::fopen(tmp.c_str(), "wb");
  if (f == nullptr) throw vsd::Error("cannot write " + path + ": " + std::strerror(errno));
  std::fclose(f);
  std::remove(tmp.c_str());
}

}  // namespace vsd_workcell
