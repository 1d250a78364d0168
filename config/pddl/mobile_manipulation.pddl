; Mobile manipulation domain of the conditional TAMP system (the paper's Move_base, Move_arm, Pick,
; Place). Symbols are bound to geometry by the graph manager:
;   location  a base pose (x, y, theta) in the world model (named locations, sampled poses)
;   region    a support surface or floor area where items rest (table top, floor patch)
;   armconf   an arm configuration: the constant `stow` (arm folded, safe for base motion) or a
;             pre-grasp configuration over a region, reachable from some base locations
;   item      a movable object of the world model (by id)
; Push: the base, arm stowed and hand empty, drives straight into an object too heavy or too wide
; to grasp and moves it along the floor; `push-to` facts are made on the fly per blocking object
; (a contact pose, a distance that clears the blocked path, the swept volume checked collision-free).
; Static facts (reaches, conf-over, graspable) come from kinematics and the world model; `occludes`
; comes from perception (an item in front of another, from the robot's approach direction).
; Action costs are placeholders (1): the graph manager prices edges with the effort estimator.
(define (domain mobile-manipulation)
  (:requirements :strips :typing :equality :negative-preconditions :universal-preconditions
                 :conditional-effects :action-costs)
  (:types location region item armconf - object)
  (:constants stow - armconf)
  (:predicates
    (robot-at ?l - location)
    (arm-at ?c - armconf)
    (hand-empty)
    (holding ?o - item)
    (on ?o - item ?r - region)
    (reaches ?l - location ?c - armconf)     ; static: from base location ?l the arm can take ?c
    (conf-over ?c - armconf ?r - region)     ; static: ?c is the pre-grasp configuration over ?r
    (graspable ?o - item)                    ; static: the gripper can hold ?o (size, mass)
    (occludes ?x - item ?o - item)           ; ?x stands in the way of grasping ?o
    ; static: from ?from, the base pushes ?o (on ?r) straight ahead to ?s, ending at ?to
    (push-to ?o - item ?r - region ?from - location ?to - location ?s - region))
  (:functions (total-cost) - number)

  (:action move_base
    :parameters (?from ?to - location)
    :precondition (and (robot-at ?from) (arm-at stow) (not (= ?from ?to)))
    :effect (and (not (robot-at ?from)) (robot-at ?to) (increase (total-cost) 1)))

  (:action move_arm
    :parameters (?l - location ?from ?to - armconf)
    :precondition (and (robot-at ?l) (arm-at ?from) (reaches ?l ?to) (not (= ?from ?to)))
    :effect (and (not (arm-at ?from)) (arm-at ?to) (increase (total-cost) 1)))

  (:action pick
    :parameters (?o - item ?r - region ?c - armconf)
    :precondition (and (arm-at ?c) (conf-over ?c ?r) (on ?o ?r) (hand-empty) (graspable ?o)
                       (forall (?x - item) (not (occludes ?x ?o))))
    :effect (and (not (on ?o ?r)) (not (hand-empty)) (holding ?o)
                 (forall (?y - item) (not (occludes ?o ?y)))
                 (increase (total-cost) 1)))

  (:action place
    :parameters (?o - item ?r - region ?c - armconf)
    :precondition (and (arm-at ?c) (conf-over ?c ?r) (holding ?o))
    :effect (and (on ?o ?r) (hand-empty) (not (holding ?o)) (increase (total-cost) 1)))

  (:action push
    :parameters (?o - item ?r - region ?from ?to - location ?s - region)
    :precondition (and (robot-at ?from) (arm-at stow) (hand-empty) (on ?o ?r) (push-to ?o ?r ?from ?to ?s))
    :effect (and (not (robot-at ?from)) (robot-at ?to) (not (on ?o ?r)) (on ?o ?s)
                 (forall (?y - item) (not (occludes ?o ?y)))
                 (increase (total-cost) 1)))
)
