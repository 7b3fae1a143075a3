# gnuplot docs/refine/refine-psnr.gp (from the repository root): docs/refine/refine-psnr.png
set terminal pngcairo size 900,420 font ",10" noenhanced
set output 'docs/refine/refine-psnr.png'
set datafile separator ','
set logscale x
set xlabel 'time budget (s of CPU time / 2 cores, CPU backend)'
set ylabel 'PSNR vs PT_MS 1024-path reference (dB)'
set key bottom right
set grid
set multiplot layout 1,2
set title 'head CT, ct-skin, 128x128, HD light converged'
plot for [m in "HD PT_MS refine_k=3 refine_k=-1"] 'docs/refine/ct-skin-warm.csv' \
     using 2:(strcol(1) eq (m eq 'refine_k=3' ? 'refine k=3' : m eq 'refine_k=-1' ? 'refine k=-1' : m) ? $3 : 1/0) \
     with linespoints title m
set title 'head CT, ct-skin, 128x128, from scratch'
plot for [m in "HD PT_MS refine_k=2 refine_k=-1"] 'docs/refine/ct-skin-scratch.csv' \
     using 2:(strcol(1) eq (m eq 'refine_k=2' ? 'refine k=2' : m eq 'refine_k=-1' ? 'refine k=-1' : m) ? $3 : 1/0) \
     with linespoints title m
unset multiplot
