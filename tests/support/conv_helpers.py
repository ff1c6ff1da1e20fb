"""Shared helpers of the conversion tests: the paper's two models, built here independently of
examples/, and one call into the checker."""

from __future__ import annotations

from fsmbt.model.bt import BTDocument, BTNode
from fsmbt.model.bt_nodes import NodeKind
from fsmbt.model.fsm import FSM

AJ_EDGES = ["AB", "AC", "AD", "AF", "BC", "BD", "CD", "DE", "EC", "ED", "EG", "GH", "FI", "IJ"]


def paper_aj_fsm() -> FSM:
    """Start->A on eventSA; A->B, A->C, A->D, A->F; B->C, B->D; C->D; D->E; E->C, E->D, E->G;
    G->H; F->I; I->J; events eventXY; H and J have no way out (final)."""
    fsm = FSM(name="paper_aj", start_name="Start", initial_event="eventSA")
    for name in "ABCDEFGHIJ":
        fsm.add_state(name, final=name in "HJ")
    for edge in AJ_EDGES:
        fsm.add_transition(edge[0], f"event{edge}", edge[1])
    return fsm


def _leaf(name: str, condition: bool) -> BTNode:
    return BTNode(type=name, kind=NodeKind.CONDITION if condition else NodeKind.ACTION)


def _control(kind: str, *children: BTNode) -> BTNode:
    return BTNode(type=kind, kind=NodeKind.CONTROL, children=list(children))


ROBOT_CONDITIONS = (
    "BatteryBelow",
    "Cube2inDelivery",
    "CubeinHand",
    "RobotatCube2",
    "RobotatDelivery",
    "RobotAtInspection",
)


def paper_robot_bt() -> BTDocument:
    """The paper's robot BT (conditions as listed in the paper, the rest actions)."""

    def leaf(name: str) -> BTNode:
        return _leaf(name, name in ROBOT_CONDITIONS)

    seq, fb = (lambda *c: _control("Sequence", *c)), (lambda *c: _control("Fallback", *c))
    root = seq(
        fb(leaf("BatteryBelow"), leaf("Recharge")),
        fb(
            leaf("Cube2inDelivery"),
            seq(
                fb(
                    leaf("CubeinHand"),
                    seq(fb(leaf("RobotatCube2"), leaf("MovetoCube2")), leaf("Pickcube2")),
                ),
                fb(leaf("RobotatDelivery"), leaf("MovetoDelivery")),
                leaf("PlaceCube2"),
            ),
        ),
        fb(leaf("RobotAtInspection"), leaf("Dock")),
    )
    return BTDocument.single(root)


def check(source, result, **options):
    """The checker's report on (source, converted)."""
    from fsmbt.verify import verify

    return verify(source, result, **options)
