"""The portal variant of the lander (``janus2d/LunarLanderPortal-v0``): a
wall and a roof box the pad in, and a portal pair is the way in. The
lander dives into portal A, an opening in the roof of a low bunker to the
left of the pad, and comes out of portal B, an opening in the pad
chamber's roof, falling toward the pad. No other engine has this: the
lander and its legs cross as one body with a clone on the far side.
"""

from __future__ import annotations

# Chamber around the pad: walls at the pad's ends, a roof 3 m above it.
ROOF_ABOVE_PAD = 3.0
ROOF_HALF_T = 0.15
PORTAL_HALF_W = 1.6


def add_portal_scenery(world, ground, pad_x):
    """Adds the pad chamber and the portal pair to a lander world.

    ``ground`` is the static ground body; ``pad_x`` the pad's ends.
    Everything here is created on ``ground`` and on two new static
    bodies, so every build creates the same handles in the same order.
    """
    from .lander import GROUND_BITS, PAD_Y, VIEW_W

    left, right = pad_x
    mid = 0.5 * (left + right)
    half = 0.5 * (right - left)
    roof_y = PAD_Y + ROOF_ABOVE_PAD
    # The chamber's walls (segments on the ground body).
    for x in (left - 0.2, right + 0.2):
        world.create_segment(ground, (x, PAD_Y), (x, roof_y), friction=0.1,
                             category_bits=GROUND_BITS)
    # Its roof: a static box whose underside carries portal B, facing down.
    roof = world.create_body("static", (mid, roof_y))
    world.create_box(roof, half + 0.4, ROOF_HALF_T, friction=0.1, category_bits=GROUND_BITS)
    # The entry: a static slab left of the chamber whose top carries
    # portal A, facing up.
    entry_x = 0.5 * (left + 0.0) if left > 4.0 else max(left - 3.0, 2.0)
    entry_x = min(entry_x, VIEW_W / 2 - half - 2.5)
    slab = world.create_body("static", (entry_x, PAD_Y + 0.8))
    world.create_box(slab, PORTAL_HALF_W + 0.3, ROOF_HALF_T, friction=0.1,
                     category_bits=GROUND_BITS)
    world.create_portal_pair(
        slab, (0.0, ROOF_HALF_T), (0.0, 1.0), PORTAL_HALF_W,
        roof, (0.0, -ROOF_HALF_T), (0.0, -1.0), PORTAL_HALF_W,
    )
