#!/usr/bin/env bash
# The paper's comparison figure as one image: one panel per task, the median training return and
# its 25-75% band over seeds against env steps, MASA, SA, SASA and MA in the colours masa_compare
# uses. Each panel reads a grid's curves (masa_compare's TASK/curves/return_METHOD.dat); a task
# without a grid gets an empty panel that says so, so the figure shows what is missing too.
#   experiments/paper_figure.sh --out FILE.png "TITLE=CURVES_DIR" ...   (CURVES_DIR may be "-": not measured)
# The gnuplot script is written beside the image (FILE.gp: `gnuplot FILE.gp` redraws it).
set -euo pipefail
out="" panels=()
while [ $# -gt 0 ]; do
  case "$1" in
    --out) out=$2; shift 2 ;;
    -*) echo "paper_figure.sh: unknown option '$1'" >&2; exit 2 ;;
    *) [[ $1 == *=* ]] || { echo "paper_figure.sh: a panel is TITLE=CURVES_DIR, got '$1'" >&2; exit 2; }
       panels+=("$1"); shift ;;
  esac
done
[ -n "$out" ] && [ ${#panels[@]} -gt 0 ] || { echo "usage: paper_figure.sh --out FILE.png TITLE=CURVES_DIR ..." >&2; exit 2; }
for p in "${panels[@]}"; do  # a mistyped directory is an error, not a task "not measured yet"
  dir=${p#*=}
  [ "$dir" = "-" ] || [ -f "$dir/return_masa.dat" ] ||
    { echo "paper_figure.sh: '$dir' has no return_masa.dat (a grid's TASK/curves folder, or - for a task not measured)" >&2; exit 2; }
done
command -v gnuplot > /dev/null || { echo "paper_figure.sh: gnuplot is not installed (scripts/install_deps.sh)" >&2; exit 2; }
methods=(masa sa sasa ma) colours=('#d62728' '#1f77b4' '#2ca02c' '#9467bd')
gp=${out%.png}.gp
n=${#panels[@]}
{
  echo "# experiments/paper_figure.sh --out $out ${panels[*]}"
  echo "set terminal pngcairo size $((440 * n)),470 font ',11'"
  echo "set output '$out.tmp'"
  echo "set termoption noenhanced"
  echo "set style fill transparent solid 0.2 noborder"
  echo "set grid"
  echo "set xlabel 'env steps (millions)'"
  echo "set format x '%g'"
  # Room at the top for one legend for the whole figure, clear of every curve.
  echo "set multiplot layout 1,$n margins 0.04,0.99,0.12,0.80 spacing 0.035,0 title 'MASA against SA, SASA and MA: training return, median and 25-75% over seeds' font ',14'"
  first=1
  for p in "${panels[@]}"; do
    title=${p%%=*} dir=${p#*=}
    echo "set title '$title'"
    if [ "$dir" = "-" ]; then
      echo "unset key; set xrange [0:1]; set yrange [0:1]; unset xtics; unset ytics"
      echo "set label 1 'not measured yet' at 0.5,0.5 center font ',13'"
      echo "plot NaN notitle"
      echo "unset label 1; set xtics; set ytics; set autoscale"
      continue
    fi
    echo "unset key"
    if [ "$first" = 1 ]; then
      # The legend once, as coloured labels across the top: a key belongs to one panel and wraps.
      for i in 0 1 2 3; do
        echo "set label $((10 + i)) '—— ${methods[$i]^^}' at screen $(awk -v i="$i" 'BEGIN { printf "%.3f", 0.41 + 0.06 * i }'),0.9 tc rgb '${colours[$i]}' font ',13'"
      done
    fi
    line="plot "
    for i in 0 1 2 3; do
      m=${methods[$i]} c=${colours[$i]} f="$dir/return_${methods[$i]}.dat"
      [ -f "$f" ] || continue
      line+="'$f' using (\$1/1e6):4:5 with filledcurves lc rgb '$c' notitle, '$f' using (\$1/1e6):3 with lines lw 2 lc rgb '$c' title '${m^^}', "
    done
    echo "${line%, }"
    first=0
  done
  echo "unset multiplot"
  echo "set output"
  echo "system('mv -f $out.tmp $out')"
} > "$gp"
gnuplot "$gp"
echo "paper_figure.sh: $out ($gp)"
