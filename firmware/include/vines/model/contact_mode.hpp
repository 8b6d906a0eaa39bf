// The contact-mode state machine of the VI NES particle: free flight, a
// finite-duration contact with the left or right wall, or riding a wall
// after a plastic impact (instantaneous law). The loop's sub-steppers
// (substep.hpp, substep_bounded.hpp) and the host's reference drivers
// (sim_host/reference: DOP853 in long double, CVODE) take the same
// transitions at an event (take_event); what a transition does to the state
// is each driver's own (its Act).
#pragma once

#include <cstdint>

namespace vines {

// Where the particle is with respect to the walls.
enum class Mode : std::uint8_t {
  kFree,
  kContactLeft,   // finite-duration contact with the left wall
  kContactRight,
  kStuckLeft,     // instantaneous law: riding the wall at zero relative speed
  kStuckRight,
};

// Below this approach speed [m/s] an instantaneous impact is taken as plastic
// and the particle rides the wall (no Zeno cascade of ever smaller bounces);
// impacts slower than it are not counted. The threshold also rises to the
// speed whose rebound, against the acceleration that pushes the particle
// into the wall, would not lift it by the contact counting depth: such
// bounces are below what the model resolves, and a cascade of them would be
// resolved one by one (hundreds of thousands of impacts).
inline constexpr double kStickSpeed = 1e-6;

// The kind of a mode, and the modes at a wall (side -1 left, +1 right).
constexpr bool in_contact(Mode m) { return m == Mode::kContactLeft || m == Mode::kContactRight; }
constexpr bool riding(Mode m) { return m == Mode::kStuckLeft || m == Mode::kStuckRight; }
constexpr Mode contact_at(int side) { return side < 0 ? Mode::kContactLeft : Mode::kContactRight; }
constexpr Mode riding_at(int side) { return side < 0 ? Mode::kStuckLeft : Mode::kStuckRight; }

// Overlap with the left and right walls for a relative position r = s - x_f
// (positive means interpenetration); dm: the device with the wall positions.
template <typename S, typename DM>
S overlap_left(const DM& dm, S r) { return dm.wall_left - r; }
template <typename S, typename DM>
S overlap_right(const DM& dm, S r) { return r - dm.wall_right; }

// What an instantaneous impact was: none (the particle does not approach
// the wall), a rebound, or plastic (the particle should ride the wall).
enum class Impact : std::uint8_t { kNone, kRebound, kPlastic };

// The transition at an event on wall `side` (-1 left, +1 right) from `mode`:
//   - free, instantaneous law (impacts): act.impact(side) applies the
//     impact; a plastic one leaves the particle riding the wall, unless the
//     wall would have to pull it there (act.pulls(side), asked with the mode
//     already riding);
//   - free, finite-duration law: a contact with that wall begins
//     (act.begin_contact(side), with the mode already the contact);
//   - in a contact: it ends once act.end_contact() says so (false: the
//     contact goes on);
//   - riding: the particle leaves the wall.
// Returns false if there was no event after all (an impact without
// approach: nothing changed).
template <typename Act>
bool take_event(Mode& mode, int side, bool impacts, Act& act) {
  switch (mode) {
    case Mode::kFree:
      if (impacts) {
        const Impact impact = act.impact(side);
        if (impact == Impact::kNone) return false;
        if (impact == Impact::kRebound) return true;
        mode = riding_at(side);
        if (act.pulls(side)) mode = Mode::kFree;
      } else {
        mode = contact_at(side);
        act.begin_contact(side);
      }
      return true;
    case Mode::kContactLeft:
    case Mode::kContactRight:
      if (act.end_contact()) mode = Mode::kFree;
      return true;
    default:
      mode = Mode::kFree;
      return true;
  }
}

}  // namespace vines
