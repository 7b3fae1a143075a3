# ct-flesh-filled.tf - examples/hd_tf.h's ct-flesh with bone filled by flesh (alpha 0.7 from 100 HU up): the
# head without its hidden-bone voids, to separate their loss from the colour (docs/EVALUATION.md,
# ct-flesh: "The main cause is the hidden bone"). Use: tf = examples/eval/ct-flesh-filled.tf
-1024 0.95 0.50 0.35 0.00
-500 0.95 0.50 0.35 0.00
-250 0.95 0.50 0.35 0.00
-100 0.95 0.50 0.35 0.60
100 0.95 0.50 0.35 0.70
3071 0.95 0.50 0.35 0.70
