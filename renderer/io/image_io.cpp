#include "renderer/io/image_io.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <random>
#include <unistd.h>

#include "renderer/io/exr_writer.h"
#include "renderer/io/oiio_module.h"
#include "renderer/io/png_writer.h"

namespace penumbra {
namespace {

std::string lower_extension(const std::string& path) {
  const size_t dot = path.find_last_of('.');
  if (dot == std::string::npos) return "";
  std::string ext = path.substr(dot + 1);
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext;
}

float srgb_to_linear(float v) {
  return v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f);
}

}  // namespace

// IEC 61966-2-1 sRGB transfer function.
float linear_to_srgb(float v) {
  if (!(v > 0.f)) return 0.f;
  if (v >= 1.f) return 1.f;
  return v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1.f / 2.4f) - 0.055f;
}

ImageFormat image_format_from_path(const std::string& path) {
  const std::string ext = lower_extension(path);
  if (ext == "png") return ImageFormat::kPng;
  if (ext == "exr") return ImageFormat::kExr;
  throw ImageIoError("unsupported image format '" + path + "' (use .png or .exr)");
}

std::vector<uint8_t> encode_image(const Image& image, ImageFormat format,
                                  const ImageMetadata& metadata) {
  const size_t n = size_t(image.width) * image.height * 3;
  if (format == ImageFormat::kPng) {
    std::vector<uint8_t> bytes(n);
    for (size_t i = 0; i < n; ++i)
      bytes[i] = uint8_t(std::lround(linear_to_srgb(image.rgb[i]) * 255.f));
    return encode_png(bytes.data(), image.width, image.height, metadata);
  }
  std::vector<float> linear(n);
  for (size_t i = 0; i < n; ++i) linear[i] = std::isfinite(image.rgb[i]) ? image.rgb[i] : 0.f;
  return encode_exr(linear.data(), image.width, image.height, metadata);
}

void write_image_file(const std::string& path, const Image& image, const ImageMetadata& metadata) {
  write_file_atomically(path, encode_image(image, image_format_from_path(path), metadata));
}

void write_file_atomically(const std::string& path, const std::vector<uint8_t>& bytes) {
  // Temporary file beside the target, then rename: readers never see a partial image.
  std::random_device rd;
  const std::string tmp = path + ".tmp." + std::to_string(::getpid()) + "." + std::to_string(rd());
  {
    std::ofstream f(tmp, std::ios::binary | std::ios::trunc);
    if (!f) throw ImageIoError("cannot write " + path);
    f.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
    f.flush();
    if (!f) {
      std::remove(tmp.c_str());
      throw ImageIoError("cannot write " + path);
    }
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    std::remove(tmp.c_str());
    throw ImageIoError("cannot write " + path);
  }
}

Image read_image_file(const std::string& path) {
  const auto in = open_plugin_image(path);
  const PenumbraImageSpec& spec = in->spec();
  if (spec.width <= 0 || spec.height <= 0 || spec.channels <= 0)
    throw ImageIoError(path + ": the image has no pixels");
  Image img(spec.width, spec.height);
  const int nc = spec.channels;
  std::vector<float> data(size_t(spec.width) * spec.height * nc);
  in->read(nc, data.data());
  const bool srgb = spec.is_uint8 != 0;
  for (size_t i = 0; i < size_t(spec.width) * spec.height; ++i)
    for (int c = 0; c < 3; ++c) {
      const float v = data[i * nc + std::min(c, nc - 1)];
      img.rgb[3 * i + c] = srgb ? srgb_to_linear(v) : v;
    }
  return img;
}

}  // namespace penumbra
