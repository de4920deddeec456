# Regenerate criteria-vs-peak-error.png from sweeps' evidence.csv (needs gnuplot):
#   python3 plot_criteria.py criteria-vs-peak-error.png hex_10x10/evidence.csv \
#       random_400/evidence.csv hex_5x5/evidence.csv hex_20x20/evidence.csv
import csv, os, subprocess, sys, tempfile

out, sources = sys.argv[1], sys.argv[2:]
# Each measure is divided by this scale (its default tolerance; 0.02 for the
# paper's form, 0.01 for the interior lateral stress error).
scales = {'force_balance': 0.008, 'moment_balance': 1e-5, 'servo': 0.0025,
          'oscillation': 1e-3, 'force_balance_paper': 0.02, 'interior_lateral': 0.01}
titles = ['force balance, up to the peak (tol 0.008)', 'moment balance (tol 1e-5)',
          'servo (tol 0.0025)', 'oscillation (tol 1e-3)',
          'paper form RMS(b_yy-s_yy)/RMS(b_yy) (at 0.02)',
          'interior lateral stress error = servo + lateral gap (at 0.01)']
styles = [(7, 6, '#1f77b4'), (9, 8, '#d62728'), (5, 4, '#2ca02c'), (13, 12, '#9467bd')]
work = tempfile.mkdtemp()
dat = os.path.join(work, 'chart.dat')
names = []
with open(dat, 'w') as f:
    for path in sources:
        names.append(os.path.basename(os.path.dirname(os.path.abspath(path))))
        for r in csv.DictReader(open(path)):
            if r['diverged'] == '1' or r['peak_error'] == 'nan':
                continue
            vals = [max(float(r[k]) / s, 1e-4) for k, s in scales.items()]
            e = max(abs(float(r['peak_error'])) * 100, 0.01)
            f.write(' '.join(f'{v:.6g}' for v in vals) + f' {e:.6g} {int(r["passed"])}\n')
        f.write('\n\n')
legend = ', '.join(f'{n} ({["circles", "triangles", "squares", "diamonds"][i]})'
                   for i, n in enumerate(names))
g = f'''set terminal pngcairo size 1500,900 font ",10" noenhanced
set output "{out}"
set multiplot layout 2,3 title "Each measure / its tolerance against |peak error| vs the converged peak. {legend}; filled = passed all four criteria"
set logscale xy
set xrange [1e-4:1e3]
set yrange [0.01:2000]
set format y "%g"
set ylabel "|peak error| [%]"
set grid
'''
for i, t in enumerate(titles):
    plots = []
    for j in range(len(names)):
        filled, empty, colour = styles[j]
        plots.append(f'"{dat}" index {j} u {i + 1}:($8==1?$7:1/0) w p pt {filled} ps 0.7 '
                     f'lc rgb "{colour}" notitle')
        plots.append(f'"{dat}" index {j} u {i + 1}:($8==0?$7:1/0) w p pt {empty} ps 0.7 '
                     f'lc rgb "{colour}" notitle')
    g += f'''set xlabel "{t} / scale"
set arrow 1 from 1,0.01 to 1,2000 nohead lc rgb "red"
set arrow 2 from 1e-4,2 to 1e3,2 nohead lc rgb "red" dt 2
plot {", ".join(plots)}
'''
g += 'unset multiplot\n'
gp = os.path.join(work, 'chart.gp')
open(gp, 'w').write(g)
subprocess.run(['gnuplot', gp], check=True)
