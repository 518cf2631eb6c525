"""The paper's equations and the load model, as pure functions of SI floats and arrays.

kinematics    travelling wave, joint angles, motor steps (eq. 43-48)
servo_gear    gear mesh, backlash, friction, reflected inertia losses (eq. 4-19)
capstan       capstan ratio, guide and contact efficiency, pull-pull tensions (eq. 20-29)
efficiency    the paper's efficiency fits and their ratio (eq. 30-35)
fidelity      position fidelity (eq. 36-40)
strouhal      Strouhal number and its penalty (eq. 41-42)
performance   eta_QP, cost of transport, transport economy (§5-6)
loads         joint torques, cable tensions, motor torque at the design point (not in the paper)
paper_audit   the paper's derived numbers, recomputed (``swiftfin audit``)
"""
