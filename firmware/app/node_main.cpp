// The board's firmware application: the link node (vines/link/node.hpp) over
// the CMSDK UART, around one compiled instance of the core whose model the
// host sends as an image (vines/link/model_plant.hpp). One image per device
// (VINES_APP_DEVICE: 0 bare frame, 1 TMD, 2 VI NES with the contact law
// VINES_APP_LAW, a struct of the registry, contact_laws.hpp), 10 stories,
// in the toolchain's scalar. The application loop is firmware/app/node_app.hpp,
// the same source the host's `vines node` runs.
// A fixed-point board (VINES_APP_FIXED, scalar "fixed" in hal/mcu/boards.txt)
// runs the Q3.28 model instead (vines/link/fixed_plant.hpp), from the
// fixed-point model image.
// Exit status (semihosting): 0 after STOP, 1 if the link stays silent.
#include "node_app.hpp"
#if VINES_APP_FIXED
#include "vines/link/fixed_plant.hpp"
#else
#include "vines/link/model_plant.hpp"
#endif

// Eigen's data layout is the same on every target (host x86-64 with SSE2 or
// AVX2, Cortex-M without SIMD): fixed-size objects 16-byte aligned.
static_assert(EIGEN_MAX_STATIC_ALIGN_BYTES == 16, "Eigen alignment differs from the other targets");

namespace {

constexpr int kStories = 10;
#if VINES_APP_DEVICE == 0
using Dev = vines::NoDevice;
#elif VINES_APP_DEVICE == 1
using Dev = vines::TmdDevice;
#elif VINES_APP_DEVICE == 2
using Dev = vines::VinesDevice<vines::laws::VINES_APP_LAW::kTag>;
#else
#error "VINES_APP_DEVICE must be 0 (bare frame), 1 (tmd) or 2 (vines, with VINES_APP_LAW)"
#endif

#if VINES_APP_FIXED
using Plant = vines::link::FixedPlant<kStories, Dev>;
#else
using Plant = vines::link::ModelPlant<VINES_APP_SCALAR, kStories, Dev>;
#endif
using Timed = vines::app::TimedPlant<Plant>;

// Static blocks: the model, the run's data and the node never live on the stack.
Plant::ModelT g_model;
Plant::DataT g_data;
Plant g_plant(&g_model, &g_data);
Timed g_timed(&g_plant);
vines::app::PortSink g_sink;
vines::link::Node<Timed, vines::app::PortSink> g_node(&g_timed, &g_sink);

}  // namespace

int main() { return vines::app::board_main(g_node, g_sink); }
