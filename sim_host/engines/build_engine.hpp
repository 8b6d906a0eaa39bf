// One way to get a built engine for a scene's parameters, and one message
// when that fails, for every command (run, sweep, stress, bench, image, hil).
#pragma once

#include <memory>
#include <stdexcept>
#include <string>

#include "sim_host/engines/engine.hpp"

namespace vines::host {

// Why an engine could not be had: "WHAT: KEY: message", where KEY names the
// scene key at fault (frame.stories when this build has no such engine,
// else the ParamError's field and index). reason() is the part after "WHAT: ".
class EngineError : public std::runtime_error {
 public:
  EngineError(const std::string& what, const std::string& reason)
      : std::runtime_error(what + ": " + reason), reason_(reason) {}
  const std::string& reason() const { return reason_; }

 private:
  std::string reason_;
};

// The engine for `p` in `scalar`, not built (for a model image to load);
// throws EngineError naming `what` if this build has none.
std::unique_ptr<Engine> engine_for(const SceneParams& p, Scalar scalar, const std::string& what);

// The engine for `p` in `scalar`, built; throws EngineError naming `what`
// (the scene file, or what the caller builds) on failure.
std::unique_ptr<Engine> build_engine(const SceneParams& p, Scalar scalar, const std::string& what);

}  // namespace vines::host
