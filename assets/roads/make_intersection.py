#!/usr/bin/env python3
"""Writes intersection.xodr: the ASAM OpenDRIVE map of scenes/intersection.toml.

A four-way junction at the map's origin. Four arms run out from the junction's edge, J = 10 m
from the centre: south (road 1, 150 m), east (2), north (3) and west (4) (100 m each), each
with a 3.5 m driving lane either way, a broken centre line, solid edge lines and a 2 m
sidewalk 12 cm high on both sides. Inside the junction, one connecting road per incoming lane
and way out: straight on (a line), left (an arc of radius J, whose lane centre turns on
J + 1.75 = 11.75 m) and right (an arc of radius J, carrying the corner's sidewalk round).

Written by seethru, dedicated to the public domain (CC0 1.0): copy it, change it, ship it.
Run it with the machine's Python (no packages) to write the map again:
    python3 assets/roads/make_intersection.py > assets/roads/intersection.xodr
"""

import math

J = 10.0  # the junction's half size, metres
LANE = 3.5  # driving lane width, metres
WALK = 2.0  # sidewalk width, metres
KERB = 0.12  # sidewalk height, metres

# id, start point (at the junction's edge), heading out of the junction, length
ARMS = [
    (1, (0.0, -J), -math.pi / 2, 150.0),
    (2, (J, 0.0), 0.0, 100.0),
    (3, (0.0, J), math.pi / 2, 100.0),
    (4, (-J, 0.0), math.pi, 100.0),
]


def num(v):
    return f"{v:.9g}" if abs(v) > 1e-12 else "0"


def lane(lane_id, kind, width, mark, height=None, link=""):
    parts = [f'<lane id="{lane_id}" type="{kind}" level="false">', link,
             f'<width sOffset="0" a="{num(width)}" b="0" c="0" d="0"/>',
             f'<roadMark sOffset="0" type="{mark}" weight="standard" color="standard" width="0.12"/>']
    if height is not None:
        parts.append(f'<height sOffset="0" inner="{num(height)}" outer="{num(height)}"/>')
    parts.append("</lane>")
    return "".join(parts)


def center(mark):
    return (f'<center><lane id="0" type="none" level="false">'
            f'<roadMark sOffset="0" type="{mark}" weight="standard" color="standard" width="0.12"/>'
            f"</lane></center>")


def arm(road_id, start, hdg, length):
    x, y = start
    left = lane(2, "sidewalk", WALK, "none", KERB) + lane(1, "driving", LANE, "solid")
    right = lane(-1, "driving", LANE, "solid") + lane(-2, "sidewalk", WALK, "none", KERB)
    return (f'<road name="arm {road_id}" length="{num(length)}" id="{road_id}" junction="-1">'
            f'<link><predecessor elementType="junction" elementId="100"/></link>'
            f'<type s="0" type="town"/>'
            f'<planView><geometry s="0" x="{num(x)}" y="{num(y)}" hdg="{num(hdg)}" length="{num(length)}"><line/></geometry></planView>'
            f"<elevationProfile/><lateralProfile/>"
            f'<lanes><laneSection s="0"><left>{left}</left>{center("broken")}<right>{right}</right></laneSection></lanes>'
            f"</road>")


def connecting(conn_id, into, out_of, turn):
    """The connecting road from arm `into` (driving into the junction) to arm `out_of`."""
    _, (x, y), hdg_out, _ = into
    hdg = hdg_out + math.pi  # into the junction
    if turn == "straight":
        length, shape = 2 * J, "<line/>"
    else:
        curvature = 1.0 / J if turn == "left" else -1.0 / J
        length, shape = math.pi * J / 2, f'<arc curvature="{num(curvature)}"/>'
    lanes = lane(-1, "driving", LANE, "none", link='<link><predecessor id="1"/><successor id="-1"/></link>')
    if turn == "right":
        lanes += lane(-2, "sidewalk", WALK, "none", KERB,
                      link='<link><predecessor id="2"/><successor id="-2"/></link>')
    return (f'<road name="{turn} from {into[0]} to {out_of[0]}" length="{num(length)}" id="{conn_id}" junction="100">'
            f'<link><predecessor elementType="road" elementId="{into[0]}" contactPoint="start"/>'
            f'<successor elementType="road" elementId="{out_of[0]}" contactPoint="start"/></link>'
            f'<type s="0" type="town"/>'
            f'<planView><geometry s="0" x="{num(x)}" y="{num(y)}" hdg="{num(hdg)}" length="{num(length)}">{shape}</geometry></planView>'
            f"<elevationProfile/><lateralProfile/>"
            f'<lanes><laneSection s="0">{center("none")}<right>{lanes}</right></laneSection></lanes>'
            f"</road>")


def main():
    roads = [arm(*a) for a in ARMS]
    connections = []
    conn_id = 101
    for i, into in enumerate(ARMS):
        # Counter-clockwise from the arm driven into: the next arm is to the right of a car
        # coming in, the one after straight on, the last to its left.
        for turn, step in (("right", 1), ("straight", 2), ("left", 3)):
            out_of = ARMS[(i + step) % 4]
            roads.append(connecting(conn_id, into, out_of, turn))
            links = '<laneLink from="1" to="-1"/>'
            if turn == "right":
                links += '<laneLink from="2" to="-2"/>'
            connections.append(
                f'<connection id="{conn_id - 100}" incomingRoad="{into[0]}" connectingRoad="{conn_id}" contactPoint="start">{links}</connection>')
            conn_id += 1
    print('<?xml version="1.0" encoding="UTF-8"?>')
    print("<!-- seethru's intersection (assets/roads/make_intersection.py writes it). CC0 1.0: public domain. -->")
    print("<OpenDRIVE>")
    print(f'<header revMajor="1" revMinor="6" name="seethru intersection" version="1" date="2026-12-06" '
          f'north="{num(J + 100)}" south="{num(-J - 150)}" east="{num(J + 100)}" west="{num(-J - 100)}" vendor="seethru"/>')
    for road in roads:
        print(road)
    print(f'<junction id="100" name="crossing">{"".join(connections)}</junction>')
    print("</OpenDRIVE>")


if __name__ == "__main__":
    main()
