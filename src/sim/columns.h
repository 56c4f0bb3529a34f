/* The one list of particle columns. Each row is X(name, C type, role,
 * needed, what): the pool struct's field, its element type, whether it is
 * STATE (copied by views, moved by swap-remove, hashed), CARRY (copied and
 * moved, not hashed: a value the state determines, kept to save work) or
 * SCRATCH (the step's own working space), the condition under which emitter `em` keeps
 * it, and what it holds. Layout, allocation, swap-remove, copies, views,
 * offsets and the state hash all expand from this list (sim/pool.c); a new
 * particle attribute is one row here, where it is written at birth, and
 * where it is read. The order is the hash's order. */
#ifndef PFX_SIM_COLUMNS_H
#define PFX_SIM_COLUMNS_H

#include "sim/birth.h"

#define PFX_POOL_COLUMNS(X)                                                                        \
    X(birth, double, STATE, true, "birth time, s: ages are one subtraction")                       \
    X(px, float, STATE, true, "position, m")                                                       \
    X(py, float, STATE, true, "")                                                                  \
    X(pz, float, STATE, true, "")                                                                  \
    X(vx, float, STATE, true, "velocity, m/s")                                                     \
    X(vy, float, STATE, true, "")                                                                  \
    X(vz, float, STATE, true, "")                                                                  \
    X(lifetime, float, STATE, true, "s; PFX_KILLED once a rule or deflector kills it")             \
    X(id, uint32_t, STATE, true, "birth index within the emitter, from 0")                         \
    X(gravity_scale, float, STATE, pfx_needs_gravity_scale(em), "random gravity multiplier")       \
    X(size0, float, STATE, pfx_needs_size0(em), "random size at birth, m")                         \
    X(size1, float, STATE, pfx_needs_size1(em), "random size at death, m")                         \
    X(charge, float, STATE, pfx_needs_charge(em), "random charge under a magnetic force, C")       \
    X(mass, float, STATE, pfx_needs_mass(em), "random mass under a magnetic force, kg")            \
    X(bx, float, STATE, pfx_needs_birth(em), "birth position, for springs anchored there")         \
    X(by, float, STATE, pfx_needs_birth(em), "")                                                   \
    X(bz, float, STATE, pfx_needs_birth(em), "")                                                   \
    X(tint, float, STATE, pfx_needs_tint(em), "random colour mix or gradient point")               \
    X(generation, float, STATE, em->keeps_generation, "sub-emitter generation (bounded cycles)")   \
    X(pr, float, STATE, em->keeps_parent_color, "colour inherited from a parent")                  \
    X(pg, float, STATE, em->keeps_parent_color, "")                                                \
    X(pb, float, STATE, em->keeps_parent_color, "")                                                \
    X(size_scale, float, STATE, em->keeps_size_scale, "size inherited from a parent")              \
    X(angle0, float, STATE, pfx_needs_angle(em), "random sprite angle at birth, rad")              \
    X(spin, float, STATE, pfx_needs_spin(em), "random spin, rad/s")                                \
    X(stuck, uint8_t, STATE, em->sticks, "1 once stuck to a deflector")                            \
    X(hits, uint32_t, STATE, pfx_needs_hit_count(em),                                              \
      "impacts so far: with the id, the key of a random resilience or friction")                   \
    X(parent_id, uint32_t, STATE, em->look.draw == PFX_DRAW_RIBBON,                                \
      "id of the particle whose trail made it: its ribbon")                                        \
    X(ax, float, CARRY, pfx_needs_carried_accel(em),                                               \
      "acceleration at the position and time, from the last kick; NaN: not known")                 \
    X(ay, float, CARRY, pfx_needs_carried_accel(em), "")                                           \
    X(az, float, CARRY, pfx_needs_carried_accel(em), "")                                           \
    X(rest, uint8_t, CARRY, em->deflector_count > 0,                                               \
      "0: awake; else at rest on the deflectors (collide.h): 1 + its contacts a step, 0x80 when "  \
      "the collide pass stores it")                                                                \
    X(rest_px, float, CARRY, em->deflector_count > 0,                                              \
      "at rest: the integrator's end state that leaves it where it is")                            \
    X(rest_py, float, CARRY, em->deflector_count > 0, "")                                          \
    X(rest_pz, float, CARRY, em->deflector_count > 0, "")                                          \
    X(rest_vx, float, CARRY, em->deflector_count > 0, "")                                          \
    X(rest_vy, float, CARRY, em->deflector_count > 0, "")                                          \
    X(rest_vz, float, CARRY, em->deflector_count > 0, "")                                          \
    X(start_px, float, SCRATCH, em->deflector_count > 0,                                           \
      "start-of-step state the collision pass sweeps from")                                        \
    X(start_py, float, SCRATCH, em->deflector_count > 0, "")                                       \
    X(start_pz, float, SCRATCH, em->deflector_count > 0, "")                                       \
    X(start_vx, float, SCRATCH, em->deflector_count > 0, "")                                       \
    X(start_vy, float, SCRATCH, em->deflector_count > 0, "")                                       \
    X(start_vz, float, SCRATCH, em->deflector_count > 0, "")                                       \
    X(near, uint8_t, SCRATCH, em->deflector_count > 0,                                             \
      "the move pass's mark: may touch a deflector this step, or stuck")

#endif
