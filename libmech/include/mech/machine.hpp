// The driven machine as the elastic drive (elastic_drive.hpp) sees it, at
// any crank angle phi: its reduced moment of inertia J(phi), half its slope,
// and its static torque at the crank split by how it follows the crank's
// direction. The drive's own twin slider-crank is one such machine written
// out by hand; mech/linkage/machine.hpp makes one of any linkage.
#pragma once
#include <stdexcept>
#include <string>

#include "mech/autodiff.hpp"
#include "mech/status.hpp"

namespace mech {

// One crank angle; each number a Dual: its value and its slope in phi.
// The torques resist the drive when positive, at the crank axis [N m]; the
// resistance while the crank turns at w2 is fixed + tanh(w2 / 1e-3)
// opposing (elastic_drive.hpp), so fixed + opposing is the static torque
// while it turns forward and fixed - opposing while it turns back.
struct MachinePoint {
  Dual inertia;     // J = 2 T / w^2 [kg m^2], with J'
  Dual half_slope;  // J' / 2 [kg m^2], with J'' / 2
  Dual fixed;       // the part the direction leaves alone (gravity, springs, constant and table loads)
  Dual opposing;    // the part that turns with the direction (opposing loads, frictions)
};

class Machine {
 public:
  virtual ~Machine() = default;
  // The machine at crank angle phi; with `slopes`, each number's slope in
  // phi too (else the slopes are 0). Throws MachineFailure where the
  // machine cannot be evaluated (a linkage that cannot assemble there).
  virtual MachinePoint state(double phi, bool slopes) const = 0;
  // Whether the drive can run it at all: ok, or the status with the reason
  // in `why` (cannot_assemble somewhere on the cycle; invalid_parameter
  // where its inertia vanishes, so that the crank's equation of motion
  // divides by zero).
  virtual Status check(std::string* why) const = 0;
};

// A machine that cannot be evaluated at an angle the drive reached: the
// drive's entry points (drive_dynamics.hpp) record `status` and the message.
class MachineFailure : public std::runtime_error {
 public:
  MachineFailure(Status s, const std::string& what) : std::runtime_error(what), status(s) {}
  Status status;
};

}  // namespace mech
