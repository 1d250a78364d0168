; The gripper already holds a cup at the start (conditional branch "gripper not empty"): it must be
; put down before the can can be picked.
(define (problem holding-start)
  (:domain mobile-manipulation)
  (:objects start near_table - location
            table - region
            over_table - armconf
            can cup - item)
  (:init (robot-at start) (arm-at stow) (holding cup)
         (on can table) (graspable can) (graspable cup)
         (reaches start stow) (reaches near_table stow) (reaches near_table over_table)
         (conf-over over_table table)
         (= (total-cost) 0))
  (:goal (and (holding can)))
  (:metric minimize (total-cost)))
