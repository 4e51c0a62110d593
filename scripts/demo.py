"""Demo: the coupled co-simulation of the two FMUs (boomsim.cosim) for experiment U (no
compensation, step 0.10: the boom oscillates) and experiment B (corrected filter, step 0.05:
stabilised), each with the feedback from t = 0 (thesis conditions) and from the CBV opening.
Writes out/<variant>.csv, out/<variant>.png, out/summary.md and out/u_against_b.png (the README's
figure: U against B, both with the feedback from t = 0)."""

import sys

from boomsim import cosim
from boomsim.paths import OUT
from boomsim.errors import cli
from boomsim.plots import plot, plot_u_against_b
from boomsim.result import write_csv
from boomsim.scenarios import load_scenario
from boomsim import metrics as mx


def fmt(x, unit=""):
    return "-" if x is None else f"{x:.3g}{unit}"


def main():
    OUT.mkdir(exist_ok=True)
    rows, first = [], {}
    for sid in ("U", "B"):
        sc = load_scenario(sid)
        for start in sc["starts"]:
            res = cosim.run(sc, "rigid", feedback_start=start)
            first.setdefault(sid, res)
            m = mx.compute(res)
            write_csv(res, OUT / f"{res.name}.csv")
            plot(res, OUT / f"{res.name}.png", m)
            rows.append((res.name, sc, m))
            print(f"{res.name}: load moves at {fmt(m['t_motion'], ' s')}, p3 settles at {fmt(m['t_settle'], ' s')}, "
                  f"p3 peak-to-peak 10-15 s {m['p3_pp_late']:.3g} bar, v {m['v_steady']:.2f} mm/s "
                  f"(expected {m['v_expected']:.2f})")
    lines = ["# boomsim demo: experiments U and B, coupled through fmpy", "",
             "HydraulicBoom (rigid boom, start stroke 480 mm, 382.6 kg payload) + PressureFeedbackController, "
             "communication step 1 ms; `-cbv` = feedback from the CBV opening instead of t = 0.", "",
             "| variant | u_ref | load moves at [s] | p3 settles (2 %) at [s] | p3 p-p 10-15 s [bar] | "
             "dominant f [Hz] | v 10-15 s [mm/s] | expected [mm/s] |",
             "| --- | --- | --- | --- | --- | --- | --- | --- |"]
    for name, sc, m in rows:
        f = f"{m['f_dom']:.2f}" if m["f_dom_amp"] >= 0.5 else "-"
        lines.append(f"| {name} | {sc['reference'][-1, 1]:+.2f} | {fmt(m['t_motion'])} | {fmt(m['t_settle'])} | "
                     f"{m['p3_pp_late']:.3g} | {f} | {m['v_steady']:.2f} | {m['v_expected']:.2f} |")
    lines += ["", "U oscillates without end (thesis 7.1); B settles and lowers at the rated flow (9.1). "
              "With the feedback from t = 0 the high-pass filter also answers the rod-side pressure build-up "
              "and holds the load for about 2.8 s (docs/python.md, \"Motion start\").", ""]
    lines += [f"![{name}]({name}.png)" for name, _, _ in rows]
    (OUT / "summary.md").write_text("\n".join(lines) + "\n")
    plot_u_against_b(first["U"], first["B"], OUT / "u_against_b.png")
    print("demo: plots, CSVs and summary.md in out/")


if __name__ == "__main__":
    sys.exit(cli(main))
