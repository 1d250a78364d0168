; NAMO: reach the goal location. The box lying on the short path may be moved (the graph manager
; decides by effort; free_patch is one floor area it may use).
(define (problem namo-corridor)
  (:domain mobile-manipulation)
  (:objects start goal near_box - location
            box_floor free_patch - region
            over_box_floor over_free_patch - armconf
            box - item)
  (:init (robot-at start) (arm-at stow) (hand-empty)
         (on box box_floor) (graspable box)
         (reaches start stow) (reaches goal stow) (reaches near_box stow)
         (reaches near_box over_box_floor) (reaches near_box over_free_patch)
         (conf-over over_box_floor box_floor) (conf-over over_free_patch free_patch)
         (= (total-cost) 0))
  (:goal (and (robot-at goal)))
  (:metric minimize (total-cost)))
