#include "sim_host/engines/build_engine.hpp"

namespace vines::host {

std::unique_ptr<Engine> engine_for(const SceneParams& p, Scalar scalar, const std::string& what) {
  std::unique_ptr<Engine> eng = make_engine(p, scalar);
  if (!eng) throw EngineError(what, "frame.stories: " + missing_engine(p, scalar));
  return eng;
}

std::unique_ptr<Engine> build_engine(const SceneParams& p, Scalar scalar, const std::string& what) {
  std::unique_ptr<Engine> eng = engine_for(p, scalar, what);
  // The ParamError names the scene key, with the element index of arrays.
  const ParamError e = eng->build(p);
  if (!e.ok()) {
    std::string key = e.field;
    if (e.index >= 0) key += "[" + std::to_string(e.index) + "]";
    throw EngineError(what, key + ": " + e.message);
  }
  return eng;
}

}  // namespace vines::host
