// Plot panels: nice ticks (Heckbert, "Nice numbers for graph labels", Graphics Gems, 1990), frames,
// labels and clipped curves.
#include "lensmith/plot/plot_axes.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace lensmith::plot {

namespace {

constexpr Rgb kGrid{0.87f, 0.87f, 0.87f};
constexpr Rgb kFrame{0.15f, 0.15f, 0.15f};
constexpr Rgb kZero{0.55f, 0.55f, 0.55f};

double nice_step(double span, int target) {
  const double raw = span / std::max(1, target);
  const double power = std::pow(10.0, std::floor(std::log10(raw)));
  const double f = raw / power;
  const double nice = f < 1.5 ? 1.0 : f < 3.0 ? 2.0 : f < 7.0 ? 5.0 : 10.0;
  return nice * power;
}

// Clips the segment ab to the rectangle (Liang-Barsky); false when nothing is left.
bool clip_segment(Point2& a, Point2& b, Point2 lo, Point2 hi) {
  double t0 = 0.0, t1 = 1.0;
  const double dx = b.x - a.x, dy = b.y - a.y;
  const double p[4] = {-dx, dx, -dy, dy};
  const double q[4] = {a.x - lo.x, hi.x - a.x, a.y - lo.y, hi.y - a.y};
  for (int i = 0; i < 4; ++i) {
    if (p[i] == 0.0) {
      if (q[i] < 0.0) return false;
      continue;
    }
    const double t = q[i] / p[i];
    if (p[i] < 0.0) {
      t0 = std::max(t0, t);
    } else {
      t1 = std::min(t1, t);
    }
    if (t0 > t1) return false;
  }
  const Point2 a0 = a;
  a = {a0.x + t0 * dx, a0.y + t0 * dy};
  b = {a0.x + t1 * dx, a0.y + t1 * dy};
  return true;
}

}  // namespace

std::vector<double> nice_ticks(double lo, double hi, int target) {
  std::vector<double> ticks;
  if (!(hi > lo) || !std::isfinite(lo) || !std::isfinite(hi)) return ticks;
  const double step = nice_step(hi - lo, target);
  const double first = std::ceil(lo / step - 1e-9) * step;
  for (double t = first; t <= hi + 1e-9 * step; t += step) ticks.push_back(std::abs(t) < 1e-12 * step ? 0.0 : t);
  return ticks;
}

AxisRange nice_range(double lo, double hi, int target) {
  if (!std::isfinite(lo) || !std::isfinite(hi)) return {0.0, 1.0};
  if (!(hi > lo)) {
    const double half = lo == 0.0 ? 1.0 : std::abs(lo) * 0.1;
    lo -= half;
    hi += half;
  }
  const double step = nice_step(hi - lo, target);
  return {std::floor(lo / step + 1e-9) * step, std::ceil(hi / step - 1e-9) * step};
}

std::string tick_label(double value, double step) {
  int decimals = 0;
  if (step > 0.0 && step < 1.0) decimals = static_cast<int>(std::ceil(-std::log10(step) - 1e-9));
  // A step of 0.25 or 2.5 needs one more digit than its power of ten.
  if (step > 0.0) {
    const double scaled = step * std::pow(10.0, decimals);
    if (std::abs(scaled - std::round(scaled)) > 1e-6) ++decimals;
  }
  char buffer[48];
  std::snprintf(buffer, sizeof buffer, "%.*f", std::clamp(decimals, 0, 10), value == 0.0 ? 0.0 : value);
  return buffer;
}

PlotAxes::PlotAxes(Canvas& canvas, Point2 top_left, Point2 bottom_right, AxisRange x, AxisRange y)
    : canvas_(canvas), top_left_(top_left), bottom_right_(bottom_right), x_(x), y_(y) {
  if (!(x_.max > x_.min)) x_ = nice_range(x_.min, x_.max);
  if (!(y_.max > y_.min)) y_ = nice_range(y_.min, y_.max);
}

Point2 PlotAxes::to_pixel(double x, double y) const {
  const double u = (x - x_.min) / (x_.max - x_.min);
  const double v = (y - y_.min) / (y_.max - y_.min);
  return {top_left_.x + u * (bottom_right_.x - top_left_.x), bottom_right_.y - v * (bottom_right_.y - top_left_.y)};
}

void PlotAxes::draw_frame(const AxesText& text, bool tick_labels_x, bool tick_labels_y, int x_ticks, int y_ticks) {
  const double fs = text.font_px;
  const std::vector<double> xt = nice_ticks(x_.min, x_.max, x_ticks);
  const std::vector<double> yt = nice_ticks(y_.min, y_.max, y_ticks);
  const double x_step = xt.size() > 1 ? xt[1] - xt[0] : x_.max - x_.min;
  const double y_step = yt.size() > 1 ? yt[1] - yt[0] : y_.max - y_.min;
  const LineStyle grid{kGrid, 1.0};
  const LineStyle tick{kFrame, 1.2};
  for (double t : text.x_tick_marks ? xt : std::vector<double>{}) {
    const Point2 p = to_pixel(t, y_.min);
    if (text.x_grid) canvas_.line({p.x, top_left_.y}, {p.x, bottom_right_.y}, grid);
    canvas_.line({p.x, bottom_right_.y}, {p.x, bottom_right_.y + 5.0}, tick);
    if (tick_labels_x) canvas_.text({p.x, bottom_right_.y + 8.0}, tick_label(t, x_step), fs * 0.85, kFrame, HAlign::Centre, VAlign::Top);
  }
  double widest_y_label = 0.0;
  for (double t : yt) {
    const Point2 p = to_pixel(x_.min, t);
    canvas_.line({top_left_.x, p.y}, {bottom_right_.x, p.y}, grid);
    canvas_.line({top_left_.x - 5.0, p.y}, {top_left_.x, p.y}, tick);
    if (tick_labels_y) {
      const std::string label = tick_label(t, y_step);
      widest_y_label = std::max(widest_y_label, canvas_.text_width(label, fs * 0.85));
      canvas_.text({top_left_.x - 8.0, p.y}, label, fs * 0.85, kFrame, HAlign::Right, VAlign::Middle);
    }
  }
  canvas_.rect(top_left_, bottom_right_, LineStyle{kFrame, 1.2});
  const double cx = 0.5 * (top_left_.x + bottom_right_.x);
  const double cy = 0.5 * (top_left_.y + bottom_right_.y);
  if (!text.title.empty()) canvas_.text({cx, top_left_.y - 8.0}, text.title, fs, kBlack, HAlign::Centre, VAlign::Bottom);
  if (!text.x_label.empty()) {
    canvas_.text({cx, bottom_right_.y + (tick_labels_x ? 12.0 + fs : 10.0)}, text.x_label, fs, kBlack, HAlign::Centre, VAlign::Top);
  }
  if (!text.y_label.empty()) {
    canvas_.text({top_left_.x - (tick_labels_y ? 16.0 + widest_y_label + 0.5 * fs : 12.0), cy}, text.y_label, fs, kBlack,
                 HAlign::Centre, VAlign::Middle, true);
  }
}

void PlotAxes::draw_zero_lines(bool horizontal, bool vertical) {
  const LineStyle style{kZero, 1.0};
  if (horizontal && y_.min < 0.0 && y_.max > 0.0) {
    const double y = to_pixel(0.0, 0.0).y;
    canvas_.line({top_left_.x, y}, {bottom_right_.x, y}, style);
  }
  if (vertical && x_.min < 0.0 && x_.max > 0.0) {
    const double x = to_pixel(0.0, 0.0).x;
    canvas_.line({x, top_left_.y}, {x, bottom_right_.y}, style);
  }
}

void PlotAxes::curve(std::span<const double> xs, std::span<const double> ys, const LineStyle& style) {
  const std::size_t n = std::min(xs.size(), ys.size());
  std::vector<Point2> run;
  auto flush = [&] {
    if (run.size() >= 2) canvas_.polyline(run, style);
    run.clear();
  };
  for (std::size_t i = 0; i + 1 < n; ++i) {
    if (!std::isfinite(xs[i]) || !std::isfinite(ys[i]) || !std::isfinite(xs[i + 1]) || !std::isfinite(ys[i + 1])) {
      flush();
      continue;
    }
    Point2 a = to_pixel(xs[i], ys[i]);
    Point2 b = to_pixel(xs[i + 1], ys[i + 1]);
    const Point2 a0 = a;
    if (!clip_segment(a, b, top_left_, bottom_right_)) {
      flush();
      continue;
    }
    // Start a new run when clipping moved the start (the curve re-enters the panel).
    if (!run.empty() && (a.x != a0.x || a.y != a0.y)) flush();
    if (run.empty()) run.push_back(a);
    run.push_back(b);
    if (b.x != to_pixel(xs[i + 1], ys[i + 1]).x || b.y != to_pixel(xs[i + 1], ys[i + 1]).y) flush();
  }
  flush();
}

void PlotAxes::dot(double x, double y, double radius_px, Rgb colour) {
  if (!std::isfinite(x) || !std::isfinite(y)) return;
  const Point2 p = to_pixel(x, y);
  if (p.x < top_left_.x || p.x > bottom_right_.x || p.y < top_left_.y || p.y > bottom_right_.y) return;
  canvas_.fill_disc(p, radius_px, colour);
}

}  // namespace lensmith::plot
