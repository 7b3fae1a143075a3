# gnuplot docs/refine/blend-256.gp (from the repository root): docs/refine/blend-256.png, the
# resting view's modes at 256^2 (scripts/eval-refine-256 and hdbench_refine's CSVs in docs/refine/)
set terminal pngcairo size 1000,760 font ",10" noenhanced
set output 'docs/refine/blend-256.png'
set datafile separator ','
set logscale x
set xlabel 'time budget (s of CPU time / 2 cores, CPU backend)'
set ylabel 'PSNR vs PT_MS reference (dB)'
set key bottom right
set grid
set multiplot layout 2,2
set title 'head CT, ct-skin, 256x256, HD light converged'
plot for [m in "HD PT_MS refine_k=-1 blend"] 'docs/refine/ct-skin-256-warm.csv' \
     using 2:(strcol(1) eq (m eq 'refine_k=-1' ? 'refine k=-1' : m) ? $3 : 1/0) with linespoints title m
set title 'head CT, ct-bone, 256x256, HD light converged'
plot for [m in "HD PT_MS refine_k=-1 blend"] 'docs/refine/ct-bone-256-warm.csv' \
     using 2:(strcol(1) eq (m eq 'refine_k=-1' ? 'refine k=-1' : m) ? $3 : 1/0) with linespoints title m
set title 'brainsmall, ramp, 256x256, HD light converged'
plot for [m in "HD PT_MS blend"] 'docs/refine/brainsmall-256-warm.csv' \
     using 2:(strcol(1) eq m ? $3 : 1/0) with linespoints title m
set title 'CGAL skull, ramp, 256x256, HD light converged'
plot for [m in "HD PT_MS blend"] 'docs/refine/skull-256-warm.csv' \
     using 2:(strcol(1) eq m ? $3 : 1/0) with linespoints title m
unset multiplot
