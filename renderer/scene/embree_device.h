#pragma once
// The process-wide Embree device (the one piece of global state the renderer keeps).
#include <embree3/rtcore.h>

#include <string>

namespace penumbra {

// Created on first use; thread-safe. Throws SceneBuildError if Embree cannot start.
RTCDevice embree_device();
// The last error Embree reported through its callback ("" if none), cleared by the call.
std::string take_embree_error();

}  // namespace penumbra
