// Embree errors are recorded per scene build: the first one, on the thread that caused it.
#include <gtest/gtest.h>

#include <future>
#include <thread>

#include "renderer/embree/device.h"
#include "renderer/embree/handles.h"

namespace penumbra::test {
namespace {

// Provokes an Embree error: more time steps than Embree allows (129).
void bad_time_steps(RTCGeometry geom) { rtcSetGeometryTimeStepCount(geom, 1000); }
// And another of a different kind: a vertex buffer in a time-step slot the geometry lacks.
void bad_buffer(RTCGeometry geom) {
  rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 7, RTC_FORMAT_FLOAT3, 12, 3);
}

TEST(EmbreeErrorScope, KeepsTheFirstError) {
  RTCDevice device = embree_device();
  EmbreeGeometry geom(rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE));
  EmbreeErrorScope scope;
  bad_time_steps(geom.get());
  const std::string first = scope.first_error();
  ASSERT_FALSE(first.empty());
  bad_buffer(geom.get());
  EXPECT_EQ(scope.first_error(), first);
}

TEST(EmbreeErrorScope, CleanBuildHasNoError) {
  EmbreeErrorScope scope;
  EmbreeGeometry geom(rtcNewGeometry(embree_device(), RTC_GEOMETRY_TYPE_TRIANGLE));
  EXPECT_TRUE(geom);
  EXPECT_EQ(scope.first_error(), "");
}

// Two builds on two threads, interleaved: one fails, then the other reads its errors, then the
// first. Each must see only its own (before, one process-wide string held the last error of any
// thread, and whoever read first took it).
TEST(EmbreeErrorScope, ThreadsDoNotSeeEachOthersErrors) {
  RTCDevice device = embree_device();
  std::string failing, clean;
  std::promise<void> failed, read;
  std::thread a([&] {
    EmbreeErrorScope scope;
    EmbreeGeometry geom(rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE));
    bad_time_steps(geom.get());
    failed.set_value();
    read.get_future().wait();
    failing = scope.first_error();
  });
  std::thread b([&] {
    EmbreeErrorScope scope;
    EmbreeGeometry geom(rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE));
    failed.get_future().wait();
    clean = scope.first_error();
    read.set_value();
  });
  a.join();
  b.join();
  EXPECT_FALSE(failing.empty());
  EXPECT_EQ(clean, "");
}

TEST(EmbreeErrorScope, NestedScopesRecordInTheInnermost) {
  EmbreeGeometry geom(rtcNewGeometry(embree_device(), RTC_GEOMETRY_TYPE_TRIANGLE));
  EmbreeErrorScope outer;
  {
    EmbreeErrorScope inner;
    bad_time_steps(geom.get());
    EXPECT_FALSE(inner.first_error().empty());
  }
  EXPECT_EQ(outer.first_error(), "");
}

}  // namespace
}  // namespace penumbra::test
