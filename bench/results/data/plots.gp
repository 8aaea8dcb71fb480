# Made by photosplat-bench: gnuplot /tmp/t/full26/data/plots.gp
set datafile separator whitespace
set logscale xy
set grid
set key top right font ',7' samplen 2 spacing 0.9
set xlabel 'seconds'
set ylabel 'relMSE'
set style line 1 lw 2 dt 1 pt 1
title0 = 'triangles 8-bit diffusion fixed'
set style line 2 lw 2 dt 1 pt 2
title1 = 'triangles 8-bit diffusion progressive'
set style line 3 lw 2 dt 1 pt 3
title2 = 'triangles float fixed'
set style line 4 lw 2 dt 1 pt 4
title3 = 'triangles float progressive'
set style line 5 lw 2 dt 1 pt 5
title4 = 'triangles+maps float fixed'
set style line 6 lw 2 dt 1 pt 6
title5 = 'triangles+maps float progressive'
set style line 7 lw 1 dt 2 pt 7
title6 = 'triangles 8-bit none fixed'
set style line 8 lw 1 dt 2 pt 1
title7 = 'triangles 8-bit counter fixed'
set style line 9 lw 1 dt 2 pt 2
title8 = 'points 8-bit diffusion fixed'
set style line 10 lw 1 dt 2 pt 3
title9 = 'points float fixed'
set style line 11 lw 1 dt 2 pt 4
title10 = 'sprites 8-bit diffusion fixed'
set style line 12 lw 1 dt 2 pt 5
title11 = 'sprites float fixed'
set terminal pngcairo size 1280,960
set output '/tmp/t/full26/bench-photons.png'
set multiplot layout 2,2
set xlabel 'photons emitted (both maps)'
set title 'cornell-caustic: whole'
plot '/tmp/t/full26/data/cornell-caustic.dat' index 0 using 8:2 with linespoints ls 1 title title0, \
     '/tmp/t/full26/data/cornell-caustic.dat' index 1 using 8:2 with linespoints ls 2 title title1, \
     '/tmp/t/full26/data/cornell-caustic.dat' index 2 using 8:2 with linespoints ls 3 title title2, \
     '/tmp/t/full26/data/cornell-caustic.dat' index 3 using 8:2 with linespoints ls 4 title title3, \
     '/tmp/t/full26/data/cornell-caustic.dat' index 4 using 8:2 with linespoints ls 5 title title4, \
     '/tmp/t/full26/data/cornell-caustic.dat' index 5 using 8:2 with linespoints ls 6 title title5, \
     '/tmp/t/full26/data/cornell-caustic.dat' index 6 using 8:2 with linespoints ls 7 title title6, \
     '/tmp/t/full26/data/cornell-caustic.dat' index 7 using 8:2 with linespoints ls 8 title title7, \
     '/tmp/t/full26/data/cornell-caustic.dat' index 8 using 8:2 with linespoints ls 9 title title8, \
     '/tmp/t/full26/data/cornell-caustic.dat' index 9 using 8:2 with linespoints ls 10 title title9, \
     '/tmp/t/full26/data/cornell-caustic.dat' index 10 using 8:2 with linespoints ls 11 title title10, \
     '/tmp/t/full26/data/cornell-caustic.dat' index 11 using 8:2 with linespoints ls 12 title title11
set title 'cornell-caustic-area: whole'
plot '/tmp/t/full26/data/cornell-caustic-area.dat' index 0 using 8:2 with linespoints ls 1 title title0, \
     '/tmp/t/full26/data/cornell-caustic-area.dat' index 1 using 8:2 with linespoints ls 2 title title1, \
     '/tmp/t/full26/data/cornell-caustic-area.dat' index 2 using 8:2 with linespoints ls 3 title title2, \
     '/tmp/t/full26/data/cornell-caustic-area.dat' index 3 using 8:2 with linespoints ls 4 title title3, \
     '/tmp/t/full26/data/cornell-caustic-area.dat' index 4 using 8:2 with linespoints ls 5 title title4, \
     '/tmp/t/full26/data/cornell-caustic-area.dat' index 5 using 8:2 with linespoints ls 6 title title5, \
     '/tmp/t/full26/data/cornell-caustic-area.dat' index 6 using 8:2 with linespoints ls 7 title title6, \
     '/tmp/t/full26/data/cornell-caustic-area.dat' index 7 using 8:2 with linespoints ls 8 title title7, \
     '/tmp/t/full26/data/cornell-caustic-area.dat' index 8 using 8:2 with linespoints ls 9 title title8, \
     '/tmp/t/full26/data/cornell-caustic-area.dat' index 9 using 8:2 with linespoints ls 10 title title9, \
     '/tmp/t/full26/data/cornell-caustic-area.dat' index 10 using 8:2 with linespoints ls 11 title title10, \
     '/tmp/t/full26/data/cornell-caustic-area.dat' index 11 using 8:2 with linespoints ls 12 title title11
set title 'ring-caustic: whole'
plot '/tmp/t/full26/data/ring-caustic.dat' index 0 using 8:2 with linespoints ls 1 title title0, \
     '/tmp/t/full26/data/ring-caustic.dat' index 1 using 8:2 with linespoints ls 2 title title1, \
     '/tmp/t/full26/data/ring-caustic.dat' index 2 using 8:2 with linespoints ls 3 title title2, \
     '/tmp/t/full26/data/ring-caustic.dat' index 3 using 8:2 with linespoints ls 4 title title3, \
     '/tmp/t/full26/data/ring-caustic.dat' index 4 using 8:2 with linespoints ls 5 title title4, \
     '/tmp/t/full26/data/ring-caustic.dat' index 5 using 8:2 with linespoints ls 6 title title5, \
     '/tmp/t/full26/data/ring-caustic.dat' index 6 using 8:2 with linespoints ls 7 title title6, \
     '/tmp/t/full26/data/ring-caustic.dat' index 7 using 8:2 with linespoints ls 8 title title7, \
     '/tmp/t/full26/data/ring-caustic.dat' index 8 using 8:2 with linespoints ls 9 title title8, \
     '/tmp/t/full26/data/ring-caustic.dat' index 9 using 8:2 with linespoints ls 10 title title9, \
     '/tmp/t/full26/data/ring-caustic.dat' index 10 using 8:2 with linespoints ls 11 title title10, \
     '/tmp/t/full26/data/ring-caustic.dat' index 11 using 8:2 with linespoints ls 12 title title11
set title 'design-room: whole'
plot '/tmp/t/full26/data/design-room.dat' index 0 using 8:2 with linespoints ls 1 title title0, \
     '/tmp/t/full26/data/design-room.dat' index 1 using 8:2 with linespoints ls 2 title title1, \
     '/tmp/t/full26/data/design-room.dat' index 2 using 8:2 with linespoints ls 3 title title2, \
     '/tmp/t/full26/data/design-room.dat' index 3 using 8:2 with linespoints ls 4 title title3, \
     '/tmp/t/full26/data/design-room.dat' index 4 using 8:2 with linespoints ls 5 title title4, \
     '/tmp/t/full26/data/design-room.dat' index 5 using 8:2 with linespoints ls 6 title title5, \
     '/tmp/t/full26/data/design-room.dat' index 6 using 8:2 with linespoints ls 7 title title6, \
     '/tmp/t/full26/data/design-room.dat' index 7 using 8:2 with linespoints ls 8 title title7, \
     '/tmp/t/full26/data/design-room.dat' index 8 using 8:2 with linespoints ls 9 title title8, \
     '/tmp/t/full26/data/design-room.dat' index 9 using 8:2 with linespoints ls 10 title title9, \
     '/tmp/t/full26/data/design-room.dat' index 10 using 8:2 with linespoints ls 11 title title10, \
     '/tmp/t/full26/data/design-room.dat' index 11 using 8:2 with linespoints ls 12 title title11
unset multiplot
set terminal pngcairo size 1280,960
set output '/tmp/t/full26/bench.png'
set multiplot layout 2,2
set xlabel 'seconds'
set title 'cornell-caustic: whole'
plot '/tmp/t/full26/data/cornell-caustic.dat' index 0 using 1:2 with linespoints ls 1 title title0, \
     '/tmp/t/full26/data/cornell-caustic.dat' index 1 using 1:2 with linespoints ls 2 title title1, \
     '/tmp/t/full26/data/cornell-caustic.dat' index 2 using 1:2 with linespoints ls 3 title title2, \
     '/tmp/t/full26/data/cornell-caustic.dat' index 3 using 1:2 with linespoints ls 4 title title3, \
     '/tmp/t/full26/data/cornell-caustic.dat' index 4 using 1:2 with linespoints ls 5 title title4, \
     '/tmp/t/full26/data/cornell-caustic.dat' index 5 using 1:2 with linespoints ls 6 title title5, \
     '/tmp/t/full26/data/cornell-caustic.dat' index 6 using 1:2 with linespoints ls 7 title title6, \
     '/tmp/t/full26/data/cornell-caustic.dat' index 7 using 1:2 with linespoints ls 8 title title7, \
     '/tmp/t/full26/data/cornell-caustic.dat' index 8 using 1:2 with linespoints ls 9 title title8, \
     '/tmp/t/full26/data/cornell-caustic.dat' index 9 using 1:2 with linespoints ls 10 title title9, \
     '/tmp/t/full26/data/cornell-caustic.dat' index 10 using 1:2 with linespoints ls 11 title title10, \
     '/tmp/t/full26/data/cornell-caustic.dat' index 11 using 1:2 with linespoints ls 12 title title11
set title 'cornell-caustic-area: whole'
plot '/tmp/t/full26/data/cornell-caustic-area.dat' index 0 using 1:2 with linespoints ls 1 title title0, \
     '/tmp/t/full26/data/cornell-caustic-area.dat' index 1 using 1:2 with linespoints ls 2 title title1, \
     '/tmp/t/full26/data/cornell-caustic-area.dat' index 2 using 1:2 with linespoints ls 3 title title2, \
     '/tmp/t/full26/data/cornell-caustic-area.dat' index 3 using 1:2 with linespoints ls 4 title title3, \
     '/tmp/t/full26/data/cornell-caustic-area.dat' index 4 using 1:2 with linespoints ls 5 title title4, \
     '/tmp/t/full26/data/cornell-caustic-area.dat' index 5 using 1:2 with linespoints ls 6 title title5, \
     '/tmp/t/full26/data/cornell-caustic-area.dat' index 6 using 1:2 with linespoints ls 7 title title6, \
     '/tmp/t/full26/data/cornell-caustic-area.dat' index 7 using 1:2 with linespoints ls 8 title title7, \
     '/tmp/t/full26/data/cornell-caustic-area.dat' index 8 using 1:2 with linespoints ls 9 title title8, \
     '/tmp/t/full26/data/cornell-caustic-area.dat' index 9 using 1:2 with linespoints ls 10 title title9, \
     '/tmp/t/full26/data/cornell-caustic-area.dat' index 10 using 1:2 with linespoints ls 11 title title10, \
     '/tmp/t/full26/data/cornell-caustic-area.dat' index 11 using 1:2 with linespoints ls 12 title title11
set title 'ring-caustic: whole'
plot '/tmp/t/full26/data/ring-caustic.dat' index 0 using 1:2 with linespoints ls 1 title title0, \
     '/tmp/t/full26/data/ring-caustic.dat' index 1 using 1:2 with linespoints ls 2 title title1, \
     '/tmp/t/full26/data/ring-caustic.dat' index 2 using 1:2 with linespoints ls 3 title title2, \
     '/tmp/t/full26/data/ring-caustic.dat' index 3 using 1:2 with linespoints ls 4 title title3, \
     '/tmp/t/full26/data/ring-caustic.dat' index 4 using 1:2 with linespoints ls 5 title title4, \
     '/tmp/t/full26/data/ring-caustic.dat' index 5 using 1:2 with linespoints ls 6 title title5, \
     '/tmp/t/full26/data/ring-caustic.dat' index 6 using 1:2 with linespoints ls 7 title title6, \
     '/tmp/t/full26/data/ring-caustic.dat' index 7 using 1:2 with linespoints ls 8 title title7, \
     '/tmp/t/full26/data/ring-caustic.dat' index 8 using 1:2 with linespoints ls 9 title title8, \
     '/tmp/t/full26/data/ring-caustic.dat' index 9 using 1:2 with linespoints ls 10 title title9, \
     '/tmp/t/full26/data/ring-caustic.dat' index 10 using 1:2 with linespoints ls 11 title title10, \
     '/tmp/t/full26/data/ring-caustic.dat' index 11 using 1:2 with linespoints ls 12 title title11
set title 'design-room: whole'
plot '/tmp/t/full26/data/design-room.dat' index 0 using 1:2 with linespoints ls 1 title title0, \
     '/tmp/t/full26/data/design-room.dat' index 1 using 1:2 with linespoints ls 2 title title1, \
     '/tmp/t/full26/data/design-room.dat' index 2 using 1:2 with linespoints ls 3 title title2, \
     '/tmp/t/full26/data/design-room.dat' index 3 using 1:2 with linespoints ls 4 title title3, \
     '/tmp/t/full26/data/design-room.dat' index 4 using 1:2 with linespoints ls 5 title title4, \
     '/tmp/t/full26/data/design-room.dat' index 5 using 1:2 with linespoints ls 6 title title5, \
     '/tmp/t/full26/data/design-room.dat' index 6 using 1:2 with linespoints ls 7 title title6, \
     '/tmp/t/full26/data/design-room.dat' index 7 using 1:2 with linespoints ls 8 title title7, \
     '/tmp/t/full26/data/design-room.dat' index 8 using 1:2 with linespoints ls 9 title title8, \
     '/tmp/t/full26/data/design-room.dat' index 9 using 1:2 with linespoints ls 10 title title9, \
     '/tmp/t/full26/data/design-room.dat' index 10 using 1:2 with linespoints ls 11 title title10, \
     '/tmp/t/full26/data/design-room.dat' index 11 using 1:2 with linespoints ls 12 title title11
unset multiplot
set terminal pngcairo size 1280,960
set output '/tmp/t/full26/cornell-caustic.png'
set multiplot layout 2,2
set xlabel 'seconds'
set title 'cornell-caustic: whole'
plot '/tmp/t/full26/data/cornell-caustic.dat' index 0 using 1:2 with linespoints ls 1 title title0, \
     '/tmp/t/full26/data/cornell-caustic.dat' index 1 using 1:2 with linespoints ls 2 title title1, \
     '/tmp/t/full26/data/cornell-caustic.dat' index 2 using 1:2 with linespoints ls 3 title title2, \
     '/tmp/t/full26/data/cornell-caustic.dat' index 3 using 1:2 with linespoints ls 4 title title3, \
     '/tmp/t/full26/data/cornell-caustic.dat' index 4 using 1:2 with linespoints ls 5 title title4, \
     '/tmp/t/full26/data/cornell-caustic.dat' index 5 using 1:2 with linespoints ls 6 title title5, \
     '/tmp/t/full26/data/cornell-caustic.dat' index 6 using 1:2 with linespoints ls 7 title title6, \
     '/tmp/t/full26/data/cornell-caustic.dat' index 7 using 1:2 with linespoints ls 8 title title7, \
     '/tmp/t/full26/data/cornell-caustic.dat' index 8 using 1:2 with linespoints ls 9 title title8, \
     '/tmp/t/full26/data/cornell-caustic.dat' index 9 using 1:2 with linespoints ls 10 title title9, \
     '/tmp/t/full26/data/cornell-caustic.dat' index 10 using 1:2 with linespoints ls 11 title title10, \
     '/tmp/t/full26/data/cornell-caustic.dat' index 11 using 1:2 with linespoints ls 12 title title11
set title 'cornell-caustic: direct'
plot '/tmp/t/full26/data/cornell-caustic.dat' index 0 using 1:3 with linespoints ls 1 title title0, \
     '/tmp/t/full26/data/cornell-caustic.dat' index 1 using 1:3 with linespoints ls 2 title title1, \
     '/tmp/t/full26/data/cornell-caustic.dat' index 2 using 1:3 with linespoints ls 3 title title2, \
     '/tmp/t/full26/data/cornell-caustic.dat' index 3 using 1:3 with linespoints ls 4 title title3, \
     '/tmp/t/full26/data/cornell-caustic.dat' index 4 using 1:3 with linespoints ls 5 title title4, \
     '/tmp/t/full26/data/cornell-caustic.dat' index 5 using 1:3 with linespoints ls 6 title title5, \
     '/tmp/t/full26/data/cornell-caustic.dat' index 6 using 1:3 with linespoints ls 7 title title6, \
     '/tmp/t/full26/data/cornell-caustic.dat' index 7 using 1:3 with linespoints ls 8 title title7, \
     '/tmp/t/full26/data/cornell-caustic.dat' index 8 using 1:3 with linespoints ls 9 title title8, \
     '/tmp/t/full26/data/cornell-caustic.dat' index 9 using 1:3 with linespoints ls 10 title title9, \
     '/tmp/t/full26/data/cornell-caustic.dat' index 10 using 1:3 with linespoints ls 11 title title10, \
     '/tmp/t/full26/data/cornell-caustic.dat' index 11 using 1:3 with linespoints ls 12 title title11
set title 'cornell-caustic: caustic'
plot '/tmp/t/full26/data/cornell-caustic.dat' index 0 using 1:4 with linespoints ls 1 title title0, \
     '/tmp/t/full26/data/cornell-caustic.dat' index 1 using 1:4 with linespoints ls 2 title title1, \
     '/tmp/t/full26/data/cornell-caustic.dat' index 2 using 1:4 with linespoints ls 3 title title2, \
     '/tmp/t/full26/data/cornell-caustic.dat' index 3 using 1:4 with linespoints ls 4 title title3, \
     '/tmp/t/full26/data/cornell-caustic.dat' index 4 using 1:4 with linespoints ls 5 title title4, \
     '/tmp/t/full26/data/cornell-caustic.dat' index 5 using 1:4 with linespoints ls 6 title title5, \
     '/tmp/t/full26/data/cornell-caustic.dat' index 6 using 1:4 with linespoints ls 7 title title6, \
     '/tmp/t/full26/data/cornell-caustic.dat' index 7 using 1:4 with linespoints ls 8 title title7, \
     '/tmp/t/full26/data/cornell-caustic.dat' index 8 using 1:4 with linespoints ls 9 title title8, \
     '/tmp/t/full26/data/cornell-caustic.dat' index 9 using 1:4 with linespoints ls 10 title title9, \
     '/tmp/t/full26/data/cornell-caustic.dat' index 10 using 1:4 with linespoints ls 11 title title10, \
     '/tmp/t/full26/data/cornell-caustic.dat' index 11 using 1:4 with linespoints ls 12 title title11
set title 'cornell-caustic: global'
plot '/tmp/t/full26/data/cornell-caustic.dat' index 0 using 1:5 with linespoints ls 1 title title0, \
     '/tmp/t/full26/data/cornell-caustic.dat' index 1 using 1:5 with linespoints ls 2 title title1, \
     '/tmp/t/full26/data/cornell-caustic.dat' index 2 using 1:5 with linespoints ls 3 title title2, \
     '/tmp/t/full26/data/cornell-caustic.dat' index 3 using 1:5 with linespoints ls 4 title title3, \
     '/tmp/t/full26/data/cornell-caustic.dat' index 4 using 1:5 with linespoints ls 5 title title4, \
     '/tmp/t/full26/data/cornell-caustic.dat' index 5 using 1:5 with linespoints ls 6 title title5, \
     '/tmp/t/full26/data/cornell-caustic.dat' index 6 using 1:5 with linespoints ls 7 title title6, \
     '/tmp/t/full26/data/cornell-caustic.dat' index 7 using 1:5 with linespoints ls 8 title title7, \
     '/tmp/t/full26/data/cornell-caustic.dat' index 8 using 1:5 with linespoints ls 9 title title8, \
     '/tmp/t/full26/data/cornell-caustic.dat' index 9 using 1:5 with linespoints ls 10 title title9, \
     '/tmp/t/full26/data/cornell-caustic.dat' index 10 using 1:5 with linespoints ls 11 title title10, \
     '/tmp/t/full26/data/cornell-caustic.dat' index 11 using 1:5 with linespoints ls 12 title title11
unset multiplot
set terminal pngcairo size 1280,960
set output '/tmp/t/full26/cornell-caustic-area.png'
set multiplot layout 2,2
set xlabel 'seconds'
set title 'cornell-caustic-area: whole'
plot '/tmp/t/full26/data/cornell-caustic-area.dat' index 0 using 1:2 with linespoints ls 1 title title0, \
     '/tmp/t/full26/data/cornell-caustic-area.dat' index 1 using 1:2 with linespoints ls 2 title title1, \
     '/tmp/t/full26/data/cornell-caustic-area.dat' index 2 using 1:2 with linespoints ls 3 title title2, \
     '/tmp/t/full26/data/cornell-caustic-area.dat' index 3 using 1:2 with linespoints ls 4 title title3, \
     '/tmp/t/full26/data/cornell-caustic-area.dat' index 4 using 1:2 with linespoints ls 5 title title4, \
     '/tmp/t/full26/data/cornell-caustic-area.dat' index 5 using 1:2 with linespoints ls 6 title title5, \
     '/tmp/t/full26/data/cornell-caustic-area.dat' index 6 using 1:2 with linespoints ls 7 title title6, \
     '/tmp/t/full26/data/cornell-caustic-area.dat' index 7 using 1:2 with linespoints ls 8 title title7, \
     '/tmp/t/full26/data/cornell-caustic-area.dat' index 8 using 1:2 with linespoints ls 9 title title8, \
     '/tmp/t/full26/data/cornell-caustic-area.dat' index 9 using 1:2 with linespoints ls 10 title title9, \
     '/tmp/t/full26/data/cornell-caustic-area.dat' index 10 using 1:2 with linespoints ls 11 title title10, \
     '/tmp/t/full26/data/cornell-caustic-area.dat' index 11 using 1:2 with linespoints ls 12 title title11
set title 'cornell-caustic-area: direct'
plot '/tmp/t/full26/data/cornell-caustic-area.dat' index 0 using 1:3 with linespoints ls 1 title title0, \
     '/tmp/t/full26/data/cornell-caustic-area.dat' index 1 using 1:3 with linespoints ls 2 title title1, \
     '/tmp/t/full26/data/cornell-caustic-area.dat' index 2 using 1:3 with linespoints ls 3 title title2, \
     '/tmp/t/full26/data/cornell-caustic-area.dat' index 3 using 1:3 with linespoints ls 4 title title3, \
     '/tmp/t/full26/data/cornell-caustic-area.dat' index 4 using 1:3 with linespoints ls 5 title title4, \
     '/tmp/t/full26/data/cornell-caustic-area.dat' index 5 using 1:3 with linespoints ls 6 title title5, \
     '/tmp/t/full26/data/cornell-caustic-area.dat' index 6 using 1:3 with linespoints ls 7 title title6, \
     '/tmp/t/full26/data/cornell-caustic-area.dat' index 7 using 1:3 with linespoints ls 8 title title7, \
     '/tmp/t/full26/data/cornell-caustic-area.dat' index 8 using 1:3 with linespoints ls 9 title title8, \
     '/tmp/t/full26/data/cornell-caustic-area.dat' index 9 using 1:3 with linespoints ls 10 title title9, \
     '/tmp/t/full26/data/cornell-caustic-area.dat' index 10 using 1:3 with linespoints ls 11 title title10, \
     '/tmp/t/full26/data/cornell-caustic-area.dat' index 11 using 1:3 with linespoints ls 12 title title11
set title 'cornell-caustic-area: caustic'
plot '/tmp/t/full26/data/cornell-caustic-area.dat' index 0 using 1:4 with linespoints ls 1 title title0, \
     '/tmp/t/full26/data/cornell-caustic-area.dat' index 1 using 1:4 with linespoints ls 2 title title1, \
     '/tmp/t/full26/data/cornell-caustic-area.dat' index 2 using 1:4 with linespoints ls 3 title title2, \
     '/tmp/t/full26/data/cornell-caustic-area.dat' index 3 using 1:4 with linespoints ls 4 title title3, \
     '/tmp/t/full26/data/cornell-caustic-area.dat' index 4 using 1:4 with linespoints ls 5 title title4, \
     '/tmp/t/full26/data/cornell-caustic-area.dat' index 5 using 1:4 with linespoints ls 6 title title5, \
     '/tmp/t/full26/data/cornell-caustic-area.dat' index 6 using 1:4 with linespoints ls 7 title title6, \
     '/tmp/t/full26/data/cornell-caustic-area.dat' index 7 using 1:4 with linespoints ls 8 title title7, \
     '/tmp/t/full26/data/cornell-caustic-area.dat' index 8 using 1:4 with linespoints ls 9 title title8, \
     '/tmp/t/full26/data/cornell-caustic-area.dat' index 9 using 1:4 with linespoints ls 10 title title9, \
     '/tmp/t/full26/data/cornell-caustic-area.dat' index 10 using 1:4 with linespoints ls 11 title title10, \
     '/tmp/t/full26/data/cornell-caustic-area.dat' index 11 using 1:4 with linespoints ls 12 title title11
set title 'cornell-caustic-area: global'
plot '/tmp/t/full26/data/cornell-caustic-area.dat' index 0 using 1:5 with linespoints ls 1 title title0, \
     '/tmp/t/full26/data/cornell-caustic-area.dat' index 1 using 1:5 with linespoints ls 2 title title1, \
     '/tmp/t/full26/data/cornell-caustic-area.dat' index 2 using 1:5 with linespoints ls 3 title title2, \
     '/tmp/t/full26/data/cornell-caustic-area.dat' index 3 using 1:5 with linespoints ls 4 title title3, \
     '/tmp/t/full26/data/cornell-caustic-area.dat' index 4 using 1:5 with linespoints ls 5 title title4, \
     '/tmp/t/full26/data/cornell-caustic-area.dat' index 5 using 1:5 with linespoints ls 6 title title5, \
     '/tmp/t/full26/data/cornell-caustic-area.dat' index 6 using 1:5 with linespoints ls 7 title title6, \
     '/tmp/t/full26/data/cornell-caustic-area.dat' index 7 using 1:5 with linespoints ls 8 title title7, \
     '/tmp/t/full26/data/cornell-caustic-area.dat' index 8 using 1:5 with linespoints ls 9 title title8, \
     '/tmp/t/full26/data/cornell-caustic-area.dat' index 9 using 1:5 with linespoints ls 10 title title9, \
     '/tmp/t/full26/data/cornell-caustic-area.dat' index 10 using 1:5 with linespoints ls 11 title title10, \
     '/tmp/t/full26/data/cornell-caustic-area.dat' index 11 using 1:5 with linespoints ls 12 title title11
unset multiplot
set terminal pngcairo size 1280,960
set output '/tmp/t/full26/ring-caustic.png'
set multiplot layout 2,2
set xlabel 'seconds'
set title 'ring-caustic: whole'
plot '/tmp/t/full26/data/ring-caustic.dat' index 0 using 1:2 with linespoints ls 1 title title0, \
     '/tmp/t/full26/data/ring-caustic.dat' index 1 using 1:2 with linespoints ls 2 title title1, \
     '/tmp/t/full26/data/ring-caustic.dat' index 2 using 1:2 with linespoints ls 3 title title2, \
     '/tmp/t/full26/data/ring-caustic.dat' index 3 using 1:2 with linespoints ls 4 title title3, \
     '/tmp/t/full26/data/ring-caustic.dat' index 4 using 1:2 with linespoints ls 5 title title4, \
     '/tmp/t/full26/data/ring-caustic.dat' index 5 using 1:2 with linespoints ls 6 title title5, \
     '/tmp/t/full26/data/ring-caustic.dat' index 6 using 1:2 with linespoints ls 7 title title6, \
     '/tmp/t/full26/data/ring-caustic.dat' index 7 using 1:2 with linespoints ls 8 title title7, \
     '/tmp/t/full26/data/ring-caustic.dat' index 8 using 1:2 with linespoints ls 9 title title8, \
     '/tmp/t/full26/data/ring-caustic.dat' index 9 using 1:2 with linespoints ls 10 title title9, \
     '/tmp/t/full26/data/ring-caustic.dat' index 10 using 1:2 with linespoints ls 11 title title10, \
     '/tmp/t/full26/data/ring-caustic.dat' index 11 using 1:2 with linespoints ls 12 title title11
set title 'ring-caustic: direct'
plot '/tmp/t/full26/data/ring-caustic.dat' index 0 using 1:3 with linespoints ls 1 title title0, \
     '/tmp/t/full26/data/ring-caustic.dat' index 1 using 1:3 with linespoints ls 2 title title1, \
     '/tmp/t/full26/data/ring-caustic.dat' index 2 using 1:3 with linespoints ls 3 title title2, \
     '/tmp/t/full26/data/ring-caustic.dat' index 3 using 1:3 with linespoints ls 4 title title3, \
     '/tmp/t/full26/data/ring-caustic.dat' index 4 using 1:3 with linespoints ls 5 title title4, \
     '/tmp/t/full26/data/ring-caustic.dat' index 5 using 1:3 with linespoints ls 6 title title5, \
     '/tmp/t/full26/data/ring-caustic.dat' index 6 using 1:3 with linespoints ls 7 title title6, \
     '/tmp/t/full26/data/ring-caustic.dat' index 7 using 1:3 with linespoints ls 8 title title7, \
     '/tmp/t/full26/data/ring-caustic.dat' index 8 using 1:3 with linespoints ls 9 title title8, \
     '/tmp/t/full26/data/ring-caustic.dat' index 9 using 1:3 with linespoints ls 10 title title9, \
     '/tmp/t/full26/data/ring-caustic.dat' index 10 using 1:3 with linespoints ls 11 title title10, \
     '/tmp/t/full26/data/ring-caustic.dat' index 11 using 1:3 with linespoints ls 12 title title11
set title 'ring-caustic: caustic'
plot '/tmp/t/full26/data/ring-caustic.dat' index 0 using 1:4 with linespoints ls 1 title title0, \
     '/tmp/t/full26/data/ring-caustic.dat' index 1 using 1:4 with linespoints ls 2 title title1, \
     '/tmp/t/full26/data/ring-caustic.dat' index 2 using 1:4 with linespoints ls 3 title title2, \
     '/tmp/t/full26/data/ring-caustic.dat' index 3 using 1:4 with linespoints ls 4 title title3, \
     '/tmp/t/full26/data/ring-caustic.dat' index 4 using 1:4 with linespoints ls 5 title title4, \
     '/tmp/t/full26/data/ring-caustic.dat' index 5 using 1:4 with linespoints ls 6 title title5, \
     '/tmp/t/full26/data/ring-caustic.dat' index 6 using 1:4 with linespoints ls 7 title title6, \
     '/tmp/t/full26/data/ring-caustic.dat' index 7 using 1:4 with linespoints ls 8 title title7, \
     '/tmp/t/full26/data/ring-caustic.dat' index 8 using 1:4 with linespoints ls 9 title title8, \
     '/tmp/t/full26/data/ring-caustic.dat' index 9 using 1:4 with linespoints ls 10 title title9, \
     '/tmp/t/full26/data/ring-caustic.dat' index 10 using 1:4 with linespoints ls 11 title title10, \
     '/tmp/t/full26/data/ring-caustic.dat' index 11 using 1:4 with linespoints ls 12 title title11
set title 'ring-caustic: global'
plot '/tmp/t/full26/data/ring-caustic.dat' index 0 using 1:5 with linespoints ls 1 title title0, \
     '/tmp/t/full26/data/ring-caustic.dat' index 1 using 1:5 with linespoints ls 2 title title1, \
     '/tmp/t/full26/data/ring-caustic.dat' index 2 using 1:5 with linespoints ls 3 title title2, \
     '/tmp/t/full26/data/ring-caustic.dat' index 3 using 1:5 with linespoints ls 4 title title3, \
     '/tmp/t/full26/data/ring-caustic.dat' index 4 using 1:5 with linespoints ls 5 title title4, \
     '/tmp/t/full26/data/ring-caustic.dat' index 5 using 1:5 with linespoints ls 6 title title5, \
     '/tmp/t/full26/data/ring-caustic.dat' index 6 using 1:5 with linespoints ls 7 title title6, \
     '/tmp/t/full26/data/ring-caustic.dat' index 7 using 1:5 with linespoints ls 8 title title7, \
     '/tmp/t/full26/data/ring-caustic.dat' index 8 using 1:5 with linespoints ls 9 title title8, \
     '/tmp/t/full26/data/ring-caustic.dat' index 9 using 1:5 with linespoints ls 10 title title9, \
     '/tmp/t/full26/data/ring-caustic.dat' index 10 using 1:5 with linespoints ls 11 title title10, \
     '/tmp/t/full26/data/ring-caustic.dat' index 11 using 1:5 with linespoints ls 12 title title11
unset multiplot
set terminal pngcairo size 1280,960
set output '/tmp/t/full26/design-room.png'
set multiplot layout 2,2
set xlabel 'seconds'
set title 'design-room: whole'
plot '/tmp/t/full26/data/design-room.dat' index 0 using 1:2 with linespoints ls 1 title title0, \
     '/tmp/t/full26/data/design-room.dat' index 1 using 1:2 with linespoints ls 2 title title1, \
     '/tmp/t/full26/data/design-room.dat' index 2 using 1:2 with linespoints ls 3 title title2, \
     '/tmp/t/full26/data/design-room.dat' index 3 using 1:2 with linespoints ls 4 title title3, \
     '/tmp/t/full26/data/design-room.dat' index 4 using 1:2 with linespoints ls 5 title title4, \
     '/tmp/t/full26/data/design-room.dat' index 5 using 1:2 with linespoints ls 6 title title5, \
     '/tmp/t/full26/data/design-room.dat' index 6 using 1:2 with linespoints ls 7 title title6, \
     '/tmp/t/full26/data/design-room.dat' index 7 using 1:2 with linespoints ls 8 title title7, \
     '/tmp/t/full26/data/design-room.dat' index 8 using 1:2 with linespoints ls 9 title title8, \
     '/tmp/t/full26/data/design-room.dat' index 9 using 1:2 with linespoints ls 10 title title9, \
     '/tmp/t/full26/data/design-room.dat' index 10 using 1:2 with linespoints ls 11 title title10, \
     '/tmp/t/full26/data/design-room.dat' index 11 using 1:2 with linespoints ls 12 title title11
set title 'design-room: direct'
plot '/tmp/t/full26/data/design-room.dat' index 0 using 1:3 with linespoints ls 1 title title0, \
     '/tmp/t/full26/data/design-room.dat' index 1 using 1:3 with linespoints ls 2 title title1, \
     '/tmp/t/full26/data/design-room.dat' index 2 using 1:3 with linespoints ls 3 title title2, \
     '/tmp/t/full26/data/design-room.dat' index 3 using 1:3 with linespoints ls 4 title title3, \
     '/tmp/t/full26/data/design-room.dat' index 4 using 1:3 with linespoints ls 5 title title4, \
     '/tmp/t/full26/data/design-room.dat' index 5 using 1:3 with linespoints ls 6 title title5, \
     '/tmp/t/full26/data/design-room.dat' index 6 using 1:3 with linespoints ls 7 title title6, \
     '/tmp/t/full26/data/design-room.dat' index 7 using 1:3 with linespoints ls 8 title title7, \
     '/tmp/t/full26/data/design-room.dat' index 8 using 1:3 with linespoints ls 9 title title8, \
     '/tmp/t/full26/data/design-room.dat' index 9 using 1:3 with linespoints ls 10 title title9, \
     '/tmp/t/full26/data/design-room.dat' index 10 using 1:3 with linespoints ls 11 title title10, \
     '/tmp/t/full26/data/design-room.dat' index 11 using 1:3 with linespoints ls 12 title title11
set title 'design-room: caustic'
plot '/tmp/t/full26/data/design-room.dat' index 0 using 1:4 with linespoints ls 1 title title0, \
     '/tmp/t/full26/data/design-room.dat' index 1 using 1:4 with linespoints ls 2 title title1, \
     '/tmp/t/full26/data/design-room.dat' index 2 using 1:4 with linespoints ls 3 title title2, \
     '/tmp/t/full26/data/design-room.dat' index 3 using 1:4 with linespoints ls 4 title title3, \
     '/tmp/t/full26/data/design-room.dat' index 4 using 1:4 with linespoints ls 5 title title4, \
     '/tmp/t/full26/data/design-room.dat' index 5 using 1:4 with linespoints ls 6 title title5, \
     '/tmp/t/full26/data/design-room.dat' index 6 using 1:4 with linespoints ls 7 title title6, \
     '/tmp/t/full26/data/design-room.dat' index 7 using 1:4 with linespoints ls 8 title title7, \
     '/tmp/t/full26/data/design-room.dat' index 8 using 1:4 with linespoints ls 9 title title8, \
     '/tmp/t/full26/data/design-room.dat' index 9 using 1:4 with linespoints ls 10 title title9, \
     '/tmp/t/full26/data/design-room.dat' index 10 using 1:4 with linespoints ls 11 title title10, \
     '/tmp/t/full26/data/design-room.dat' index 11 using 1:4 with linespoints ls 12 title title11
set title 'design-room: global'
plot '/tmp/t/full26/data/design-room.dat' index 0 using 1:5 with linespoints ls 1 title title0, \
     '/tmp/t/full26/data/design-room.dat' index 1 using 1:5 with linespoints ls 2 title title1, \
     '/tmp/t/full26/data/design-room.dat' index 2 using 1:5 with linespoints ls 3 title title2, \
     '/tmp/t/full26/data/design-room.dat' index 3 using 1:5 with linespoints ls 4 title title3, \
     '/tmp/t/full26/data/design-room.dat' index 4 using 1:5 with linespoints ls 5 title title4, \
     '/tmp/t/full26/data/design-room.dat' index 5 using 1:5 with linespoints ls 6 title title5, \
     '/tmp/t/full26/data/design-room.dat' index 6 using 1:5 with linespoints ls 7 title title6, \
     '/tmp/t/full26/data/design-room.dat' index 7 using 1:5 with linespoints ls 8 title title7, \
     '/tmp/t/full26/data/design-room.dat' index 8 using 1:5 with linespoints ls 9 title title8, \
     '/tmp/t/full26/data/design-room.dat' index 9 using 1:5 with linespoints ls 10 title title9, \
     '/tmp/t/full26/data/design-room.dat' index 10 using 1:5 with linespoints ls 11 title title10, \
     '/tmp/t/full26/data/design-room.dat' index 11 using 1:5 with linespoints ls 12 title title11
unset multiplot
