; Pick the can behind two other objects on a cluttered table and bring it to the counter.
(define (problem occluded-can)
  (:domain mobile-manipulation)
  (:objects start near_table near_counter - location
            table counter - region
            over_table over_counter - armconf
            can box cup - item)
  (:init (robot-at start) (arm-at stow) (hand-empty)
         (on can table) (on box table) (on cup table)
         (graspable can) (graspable box) (graspable cup)
         (occludes box can) (occludes cup can)
         (reaches start stow) (reaches near_table stow) (reaches near_counter stow)
         (reaches near_table over_table) (reaches near_counter over_counter)
         (conf-over over_table table) (conf-over over_counter counter)
         (= (total-cost) 0))
  (:goal (and (on can counter)))
  (:metric minimize (total-cost)))
