// The ustar header the frames archive is made of (server/http/tar_header.h) and the frames'
// names in it (server/http/frame_archive.h): fields at their POSIX offsets, the checksum, refusals.
#include "server/http/tar_header.h"

#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

#include "server/http/frame_archive.h"

namespace penumbra::test {
namespace {

std::string field(const std::array<char, 512>& h, std::size_t at, std::size_t width) {
  return std::string(h.data() + at, width);
}

TEST(TarHeader, FieldsSitWhereUstarPutsThem) {
  const auto h = server::tar_file_header("frame_0017.exr", 7499, 1796097346);
  EXPECT_EQ(field(h, 0, 15), std::string("frame_0017.exr\0", 15));
  EXPECT_EQ(field(h, 100, 8), std::string("0000644\0", 8));
  EXPECT_EQ(field(h, 124, 12), std::string("00000016513\0", 12));  // 7499 in octal
  EXPECT_EQ(field(h, 136, 12), std::string("15303442502\0", 12));  // 1796097346 in octal
  EXPECT_EQ(h[156], '0');
  EXPECT_EQ(field(h, 257, 8), std::string("ustar\0" "00", 8));
  unsigned sum = 0;
  for (std::size_t i = 0; i < 512; ++i)
    sum += (i >= 148 && i < 156) ? unsigned(' ') : static_cast<unsigned char>(h[i]);
  EXPECT_EQ(std::stoul(field(h, 148, 6), nullptr, 8), sum);
  EXPECT_EQ(h[154], '\0');
  EXPECT_EQ(h[155], ' ');
  EXPECT_EQ(server::tar_padded(0), 0u);
  EXPECT_EQ(server::tar_padded(1), 512u);
  EXPECT_EQ(server::tar_padded(512), 512u);
  EXPECT_EQ(server::tar_padded(7499), 7680u);
}

TEST(TarHeader, RefusesWhatUstarCannotHold) {
  EXPECT_THROW(server::tar_file_header("", 1, 0), std::invalid_argument);
  EXPECT_THROW(server::tar_file_header(std::string(101, 'a'), 1, 0), std::invalid_argument);
  EXPECT_NO_THROW(server::tar_file_header(std::string(100, 'a'), 1, 0));
  EXPECT_THROW(server::tar_file_header("a/b", 1, 0), std::invalid_argument);
  EXPECT_NO_THROW(server::tar_file_header("big", server::kTarMaxFileBytes, 0));
  EXPECT_THROW(server::tar_file_header("big", server::kTarMaxFileBytes + 1, 0), std::invalid_argument);
}

TEST(FrameArchiveNames, PaddedAsBlenderAndWiderWhenNeeded) {
  EXPECT_EQ(server::frame_digits(1, 48), 4);
  EXPECT_EQ(server::frame_digits(1, 123456), 6);
  EXPECT_EQ(server::frame_digits(-20000, 3), 5);
  EXPECT_EQ(server::frame_file_name(17, 4, "exr"), "frame_0017.exr");
  EXPECT_EQ(server::frame_file_name(17, 4, "albedo.png"), "frame_0017.albedo.png");
  EXPECT_EQ(server::frame_file_name(123456, 6, "exr"), "frame_123456.exr");
  EXPECT_EQ(server::frame_file_name(-3, 4, "exr"), "frame_-0003.exr");
}

}  // namespace
}  // namespace penumbra::test
