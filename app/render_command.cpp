// penumbra render SCENE.json -o OUT.{png,exr} [overrides] [--window x0,y0,x1,y1] [--frame N | --frames]
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <string>
#include <vector>
#include <unistd.h>

#include "api/animation_parser.h"
#include "api/scene_loader.h"
#include "api/version.h"
#include "app/commands.h"
#include "app/load_report.h"
#include "app/option_parsing.h"
#include "renderer/io/image_io.h"
#include "renderer/io/layer_io.h"
#include "renderer/render/render.h"

namespace penumbra::app {
namespace {

const char* kUsage =
    "usage: penumbra render SCENE.json -o OUT.{png,exr} [options]\n"
    "       penumbra render MODEL.{glb,gltf} -o OUT.{png,exr} [options]\n"
    "\n"
    "Renders a scene (format v1, see docs/scene-format.md). Options override the scene's\n"
    "\"render\" settings and are checked as those fields are, with the same limits:\n"
    "  -o, --output FILE        output image; .png (sRGB 8-bit) or .exr (linear float)\n"
    "  --spp N                  samples per pixel\n"
    "  --width N, --height N    image size in pixels\n"
    "  --seed N                 sampler seed (same seed, same image, any thread count)\n"
    "  --threads N              render threads (default: all cores)\n"
    "  --max-depth N            path segments (-1 = unlimited)\n"
    "  --rr-depth N             depth at which Russian roulette starts\n"
    "  --integrator NAME        path | distributed\n"
    "  --sampler NAME           auto | cmj | sobol: correlated multi-jittered points for\n"
    "                           uniform renders of a power-of-two spp (auto's choice), Sobol\n"
    "                           points otherwise (docs/scene-format.md)\n"
    "  --path-reuse N           blocks of N x N pixels share their paths' second vertices\n"
    "                           (1 = off, up to 4; docs/scene-format.md)\n"
    "  --time-limit SECONDS     stop at this budget with a correct (less converged) image\n"
    "  --noise-threshold X      adaptive sampling: aim for this relative RMS error (0.05 = 5%);\n"
    "                           samples go where the noise is, spp is the per-pixel cap\n"
    "  --aov LIST               output layers beside the image, comma-separated:\n"
    "                           albedo,normal,depth (docs/output-layers.md)\n"
    "  --layout NAME            where the layers go: plain (default; .exr: extra channels\n"
    "                           albedo.R, normal.X, depth.Z; .png: one file per layer,\n"
    "                           OUT.albedo.png ...), blender (.exr: Blender's multi-layer\n"
    "                           names, ViewLayer.Combined.R ...), separate (one file per layer)\n"
    "  --denoise                denoise the image with Intel Open Image Denoise, guided by\n"
    "                           albedo and normal; the image as rendered (unbiased) is kept\n"
    "                           as the layer noisy (docs/denoising.md)\n"
    "  --window X0,Y0,X1,Y1     render only pixels X0..X1-1, Y0..Y1-1 of the image (a part of\n"
    "                           a frame split across machines): .exr keeps them as the data\n"
    "                           window of the whole frame, .png holds the window's pixels;\n"
    "                           join the parts with penumbra merge (docs/animation-and-windows.md)\n"
    "  --frame N                render frame N of the scene's \"animation\"\n"
    "  --frames                 render every frame of the animation, one file each: OUT must\n"
    "                           hold a # pattern, out_####.exr -> out_0017.exr\n"
    "  --scalar                 advance one path at a time, one ray at a time (the reference\n"
    "                           driver; the default advances batches of paths a bounce at a\n"
    "                           time with rays traced in packets; both give the same image)\n"
    "  -q, --quiet              no progress bar\n";

enum class Layout { kPlain, kBlender, kSeparate };

int render_one(const std::string& scene_path, const std::string& output, ImageFormat format,
               Layout layout, bool quiet, const api::SceneRequest& request,
               std::optional<int64_t> frame);

std::string format_duration(double s) {
  char buf[32];
  if (s < 60) std::snprintf(buf, sizeof buf, "%.1fs", s);
  else if (s < 3600) std::snprintf(buf, sizeof buf, "%dm%02ds", int(s) / 60, int(s) % 60);
  else std::snprintf(buf, sizeof buf, "%dh%02dm", int(s) / 3600, int(s) / 60 % 60);
  return buf;
}

}  // namespace

int run_render(int argc, char** argv) {
  std::string scene_path, output;
  bool quiet = false;
  std::optional<int64_t> frame;
  bool all_frames = false;
  bool scalar = false;
  std::string layout_name = "plain";
  std::vector<api::RenderOverride> overrides;
  OptionParser p(argc, argv);
  while (p.next()) {
    if (p.is("-h") || p.is("--help")) {
      std::fputs(kUsage, stdout);
      return 0;
    } else if (p.is("-o") || p.is("--output")) {
      if (!p.value(&output)) return p.fail(kUsage);
    } else if (p.is("--layout")) {
      if (!p.value(&layout_name)) return p.fail(kUsage);
    } else if (p.is("--frame")) {
      long long n = 0;
      if (!p.int_value(-1'000'000'000, 1'000'000'000, &n)) return p.fail(kUsage);
      frame = n;
    } else if (p.is("--frames")) {
      all_frames = true;
    } else if (p.is("--scalar")) {
      scalar = true;
    } else if (p.is("-q") || p.is("--quiet")) {
      quiet = true;
    } else if (parse_render_override(p, overrides)) {
      if (p.failed()) return p.fail(kUsage);
    } else if (p.positional()) {
      if (!scene_path.empty()) return p.fail(kUsage, "more than one scene given");
      scene_path = p.arg();
    } else {
      return p.fail(kUsage, "unknown option " + std::string(p.arg()));
    }
  }
  if (scene_path.empty() || output.empty())
    return p.fail(kUsage, scene_path.empty() ? "no scene given" : "no output given (-o)");
  if (frame && all_frames) return p.fail(kUsage, "--frame and --frames exclude each other");
  if (all_frames && !api::has_frame_pattern(output))
    return p.fail(kUsage, "--frames writes one file per frame: give -o a # pattern (out_####.exr)");
  // Reject an unsupported output name or layout before spending time on the render.
  ImageFormat format;
  try {
    format = image_format_from_path(output);
  } catch (const ImageIoError& e) {
    std::fprintf(stderr, "penumbra render: %s\n", e.what());
    return 2;
  }
  Layout layout;
  if (layout_name == "plain") layout = format == ImageFormat::kPng ? Layout::kSeparate : Layout::kPlain;
  else if (layout_name == "separate") layout = Layout::kSeparate;
  else if (layout_name == "blender" && format == ImageFormat::kExr) layout = Layout::kBlender;
  else if (layout_name == "blender")
    return p.fail(kUsage, "--layout blender writes a multi-layer EXR: give -o NAME.exr");
  else
    return p.fail(kUsage, "unknown --layout " + layout_name + " (plain, blender or separate)");

  api::LoadResult loaded = api::load_scene_file(scene_path, {}, overrides);
  if (!report_load_problems(scene_path, loaded)) return 1;
  api::SceneRequest& request = *loaded.request;
  if (scalar) request.settings.wavefront = false;

  // Which frames: --frame N, --frames (all), or none (a scene with an animation renders its
  // first frame, as load_scene left it).
  std::vector<int64_t> frames;
  if (frame) {
    frames.push_back(*frame);
  } else if (all_frames) {
    if (!request.animation) {
      std::fprintf(stderr, "%s: --frames: the scene has no \"animation\": there are no frames to render\n",
                   scene_path.c_str());
      return 1;
    }
    for (int64_t f = request.animation->first_frame; f <= request.animation->last_frame; ++f) frames.push_back(f);
  }
  if (frames.empty()) {
    const int64_t f = request.animation ? request.animation->first_frame : 0;
    const std::string path = request.animation ? api::frame_path(output, f) : output;
    return render_one(scene_path, path, format, layout, quiet, request,
                      request.animation ? std::optional<int64_t>(f) : std::nullopt);
  }
  for (const int64_t f : frames) {
    api::Diagnostics diag;
    if (!api::select_frame(request, f, diag, frame ? "--frame" : "--frames")) {
      for (const api::Diagnostic& d : diag.take_errors())
        std::fprintf(stderr, "%s: %s\n", scene_path.c_str(), d.to_string().c_str());
      return 1;
    }
    if (const int rc = render_one(scene_path, api::frame_path(output, f), format, layout, quiet, request, f))
      return rc;
  }
  return 0;
}

namespace {

int render_one(const std::string& scene_path, const std::string& output, ImageFormat format,
               Layout layout, bool quiet, const api::SceneRequest& request,
               std::optional<int64_t> frame) {
  const RenderSettings& settings = request.settings;

  const auto build_start = std::chrono::steady_clock::now();
  const auto scene = Scene::build(request.scene);
  scene->prepare_sampling(settings.integrator);
  const double build_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - build_start).count();

  const bool show_progress = !quiet && isatty(STDERR_FILENO);
  auto last_draw = std::chrono::steady_clock::now() - std::chrono::seconds(1);
  RenderControl control;
  if (!quiet) {
    control.on_progress = [&](const RenderProgress& pr) {
      const auto now = std::chrono::steady_clock::now();
      if (now - last_draw < std::chrono::milliseconds(show_progress ? 100 : 2000) && pr.fraction < 1.0)
        return;
      last_draw = now;
      const int width = 30, filled = int(pr.fraction * width);
      const double rate = pr.elapsed_seconds > 0 ? pr.samples_done / pr.elapsed_seconds : 0.0;
      std::fprintf(stderr, "%s[%.*s%*s] %5.1f%%  %.2f Msamples/s  ETA %s%s",
                   show_progress ? "\r" : "", filled, "##############################",
                   width - filled, "", pr.fraction * 100.0, rate * 1e-6,
                   format_duration(pr.eta_seconds).c_str(), show_progress ? "" : "\n");
      std::fflush(stderr);
    };
  }
  const RenderResult result = render(*scene, settings, control);
  if (show_progress) std::fputc('\n', stderr);
  const RenderStats& st = result.stats;

  ImageMetadata meta = {
      {"penumbra:spp", std::to_string(settings.spp)},
      {"penumbra:spp_mean", std::to_string(st.spp_mean)},
      {"penumbra:render_seconds", std::to_string(st.seconds)},
      {"penumbra:seed", std::to_string(settings.seed)},
      {"penumbra:integrator", settings.integrator == IntegratorKind::kPath ? "path" : "distributed"},
      {"Software", api::kSoftwareName},
  };
  if (frame) meta.push_back({"penumbra:frame", std::to_string(*frame)});
  // A window is written as the data window of the whole frame (EXR; a PNG holds its pixels).
  const PixelWindow display{0, 0, settings.width, settings.height};
  const PixelWindow* data_window = settings.window ? &result.window : nullptr;
  const PixelWindow* display_window = settings.window ? &display : nullptr;
  const int out_width = result.image.width, out_height = result.image.height;
  if (settings.denoise) {
    meta.push_back({"penumbra:denoised", st.denoised ? "true" : "false"});
    if (!st.denoised)
      std::fprintf(stderr, "penumbra render: warning: the image is not denoised: %s\n",
                   st.denoise_error.c_str());
  }
  try {
    if (layout == Layout::kSeparate || (result.layers.empty() && layout == Layout::kPlain)) {
      if (format == ImageFormat::kExr)
        write_file_atomically(output, encode_layered_exr(result.image, {}, ExrLayout::kPlain, meta,
                                                         data_window, display_window));
      else
        write_image_file(output, result.image, meta);
      for (const ImageLayer& layer : result.layers)
        write_file_atomically(layer_file_path(output, layer.name),
                              encode_layer(layer, out_width, out_height, format, meta, data_window,
                                           display_window));
    } else {
      write_file_atomically(output, encode_layered_exr(result.image, result.layers,
                                                       layout == Layout::kBlender ? ExrLayout::kBlender
                                                                                  : ExrLayout::kPlain,
                                                       meta, data_window, display_window));
    }
  } catch (const ImageIoError& e) {
    std::fprintf(stderr, "penumbra render: %s\n", e.what());
    return 1;
  }
  std::fprintf(stderr,
               "rendered %s%s -> %s: %dx%d, %.1f spp (min %d, max %d), %.3f s (+%.3f s build), "
               "%.2f Mrays/s%s%s%s\n",
               scene_path.c_str(), frame ? (" frame " + std::to_string(*frame)).c_str() : "",
               output.c_str(), out_width, out_height, st.spp_mean,
               st.spp_min, st.spp_max, st.seconds, build_seconds, st.mrays_per_second(),
               st.stopped_by_time_limit ? ", stopped at the time limit" : "",
               st.denoised ? (", denoised in " + std::to_string(st.denoise_seconds).substr(0, 5) +
                              " s").c_str()
                           : "",
               st.nonfinite_samples ? (", " + std::to_string(st.nonfinite_samples) +
                                       " non-finite samples dropped").c_str()
                                    : "");
  return 0;
}

}  // namespace

}  // namespace penumbra::app
