// The engines of this build (peers.hpp).
#include "peers.hpp"

namespace plate::peers {

std::vector<Engine> engines() {
    std::vector<Engine> e;
#ifdef PLATE_PEER_BULLET
    e.push_back({"Bullet", &run_bullet});
#endif
#ifdef PLATE_PEER_ODE
    e.push_back({"ODE", &run_ode});
#endif
#ifdef PLATE_PEER_MUJOCO
    e.push_back({"MuJoCo", &run_mujoco});
#endif
    return e;
}

}   // namespace plate::peers
