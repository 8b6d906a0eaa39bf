// The boards' twin image: the link node (vines/link/node.hpp) over the CMSDK
// UART around the twin estimator alone (vines/link/twin_plant.hpp), up to 10
// stories, in the toolchain's scalar. A monitoring node needs no simulation
// model: the twin image the host designs (docs/twin.md) says the device's
// kind (bare frame, TMD, VI NES), so one image serves every building. The
// application loop is firmware/app/node_app.hpp, as for the device images.
// Exit status (semihosting): 0 after STOP, 1 if the link stays silent.
#include "node_app.hpp"
#include "vines/link/twin_plant.hpp"

namespace {

using Scalar = VINES_APP_SCALAR;
constexpr int kStories = 10;

using Plant = vines::link::TwinPlant<Scalar, kStories>;
using Timed = vines::app::TimedPlant<Plant>;

// Static blocks: the estimator and the node never live on the stack.
Plant g_plant;
Timed g_timed(&g_plant);
vines::app::PortSink g_sink;
vines::link::Node<Timed, vines::app::PortSink> g_node(&g_timed, &g_sink);

}  // namespace

int main() { return vines::app::board_main(g_node, g_sink); }
