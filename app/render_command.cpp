// penumbra render SCENE.json -o OUT.{png,exr} [overrides]
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>
#include <unistd.h>

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
    "  -q, --quiet              no progress bar\n";

enum class Layout { kPlain, kBlender, kSeparate };

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
  const RenderSettings& settings = loaded.request->settings;

  const auto build_start = std::chrono::steady_clock::now();
  const auto scene = Scene::build(loaded.request->scene);
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
  if (settings.denoise) {
    meta.push_back({"penumbra:denoised", st.denoised ? "true" : "false"});
    if (!st.denoised)
      std::fprintf(stderr, "penumbra render: warning: the image is not denoised: %s\n",
                   st.denoise_error.c_str());
  }
  try {
    if (layout == Layout::kSeparate || (result.layers.empty() && layout == Layout::kPlain)) {
      write_image_file(output, result.image, meta);
      for (const ImageLayer& layer : result.layers)
        write_file_atomically(layer_file_path(output, layer.name),
                              encode_layer(layer, settings.width, settings.height, format, meta));
    } else {
      write_file_atomically(output, encode_layered_exr(result.image, result.layers,
                                                       layout == Layout::kBlender ? ExrLayout::kBlender
                                                                                  : ExrLayout::kPlain,
                                                       meta));
    }
  } catch (const ImageIoError& e) {
    std::fprintf(stderr, "penumbra render: %s\n", e.what());
    return 1;
  }
  std::fprintf(stderr,
               "rendered %s -> %s: %dx%d, %.1f spp (min %d, max %d), %.3f s (+%.3f s build), "
               "%.2f Mrays/s%s%s%s\n",
               scene_path.c_str(), output.c_str(), settings.width, settings.height, st.spp_mean,
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

}  // namespace penumbra::app
