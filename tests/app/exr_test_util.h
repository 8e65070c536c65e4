#pragma once
// Reading back the EXR files the CLI writes, with OpenEXR: channel names and one channel's values.
#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>

#include <set>
#include <string>
#include <vector>

namespace penumbra::test {

inline std::set<std::string> exr_channels(const std::string& path) {
  const Imf::InputFile input(path.c_str());
  std::set<std::string> names;
  for (auto it = input.header().channels().begin(); it != input.header().channels().end(); ++it)
    names.insert(it.name());
  return names;
}

// One channel's values, rows top to bottom.
inline std::vector<float> read_exr_channel(const std::string& path, const std::string& name) {
  Imf::InputFile input(path.c_str());
  const Imath::Box2i dw = input.header().dataWindow();
  const int w = dw.max.x - dw.min.x + 1, h = dw.max.y - dw.min.y + 1;
  std::vector<float> data(size_t(w) * h);
  Imf::FrameBuffer fb;
  fb.insert(name, Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(data.data()), sizeof(float),
                             sizeof(float) * size_t(w)));
  input.setFrameBuffer(fb);
  input.readPixels(dw.min.y, dw.max.y);
  return data;
}

}  // namespace penumbra::test
