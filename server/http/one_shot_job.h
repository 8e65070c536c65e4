#pragma once
// The one-shot forms of POST /v1/jobs (issue 12), for curl:
//   curl -F scene=@scene.json -F bunny.ply=@bunny.ply .../v1/jobs     (multipart/form-data: the
//        part "scene" is the scene, every other part a file under its part name)
//   curl --data-binary @model.glb -H 'Content-Type: model/gltf-binary' '.../v1/jobs?width=640'
//        (a self-contained glTF, rendered as `penumbra render model.glb` would, with the render
//        block's members as query parameters)
// Both store their files in the asset store and become the ordinary job envelope
// {"scene": ..., "assets": {...}} (api/job_submission.h), so they meet every check a JSON job
// does; error pointers "/scene/..." point into the scene part, "/assets/NAME" to the part NAME.
#include <string>
#include <variant>

#include "server/http/problem.h"
#include "server/http/route_context.h"

namespace httplib {
struct Request;
}

namespace penumbra::server {

// The request header the guard moves a one-shot form's Content-Type to (request_guard.cpp),
// so cpp-httplib does not parse the multipart body itself.
inline constexpr const char* kOneShotTypeHeader = "Penumbra-Form-Content-Type";
// The Content-Type such a request carries meanwhile: the library reads it as a plain body.
inline constexpr const char* kOneShotMarkerType = "application/x-penumbra-one-shot";

// True when the request is one of the one-shot forms.
bool is_one_shot_job(const httplib::Request& req);
// The job envelope to submit, or the problem to answer.
std::variant<std::string, Problem> one_shot_job_body(const RouteContext& c,
                                                     const httplib::Request& req);

}  // namespace penumbra::server
