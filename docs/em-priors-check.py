#!/usr/bin/env python3
"""EM with and without a prior on the sonar's scale, on the checked-in straight-board scenarios
(which draw a speed-scale error of the drive per seed), against the true lidar model.

    python3 docs/em-priors-check.py target/release/hilsim

For each scenario and seeds 1-8: the MSE ratio (eq. 31 of the landmark paper) of the target
beam's raw readings inverted through EM's lidar model without a prior, with
`--prior sonar.alpha1=1.028±0.003` (the scenarios' sonar scale), and through the declared (true)
lidar model, all against the simulator's true ranges.
"""
import json, csv, subprocess, sys, os, tempfile
H = os.path.abspath(sys.argv[1])
ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
TMP = tempfile.mkdtemp()
# The scenarios' declared lidar bias ([sensors.lidar] bias).
true_alpha=[0.0525,0.8838,0.0584]
def inv(a,y):
    a0,a1,a2=a; c=a0-y
    if abs(a2)<1e-12: return -c/a1
    disc=a1*a1-4*a2*c
    if disc<0: return float('nan')
    return (-a1+disc**0.5)/(2*a2)
def ratio(rec,a):
    raw=cal=0;n=0
    for r in csv.DictReader(open(rec+'/lidar.csv')):
        if r['angle_deg']!='0' or r['invalid']!='0': continue
        y=float(r['range_m']); d=float(r['true_range_m'])
        raw+=(y-d)**2; cal+=(inv(a,y)-d)**2; n+=1
    return raw/cal
rows=[]
for sc in ['straight-board','straight-board-0.2','straight-board-0.3']:
    for seed in range(1,9):
        rec=f'{TMP}/{sc}-{seed}'
        subprocess.run([H,'record',f'{ROOT}/scenarios/{sc}.toml','--seed',str(seed),'--out',rec],check=True,capture_output=True)
        def em(extra):
            p=subprocess.run([H,'calibrate',rec,'--method','em','--json']+extra,capture_output=True,text=True)
            return json.loads(p.stdout)['sensors']['lidar']['alpha']
        r_none=ratio(rec,em([]))
        r_prior=ratio(rec,em(['--prior','sonar.alpha1=1.028±0.003']))
        r_true=ratio(rec,true_alpha)
        rows.append((sc,seed,r_none,r_prior,r_true))
        print(f'{sc:20s} {seed} no-prior {r_none:7.1f} prior {r_prior:7.1f} true {r_true:7.1f}  prior/no {r_prior/r_none:5.2f} prior/true {r_prior/r_true:5.2f}',flush=True)
import statistics as st
print('median prior/no-prior', st.median(r[3]/r[2] for r in rows), 'median prior/true', st.median(r[3]/r[4] for r in rows))
print('min prior/no-prior', min(r[3]/r[2] for r in rows), 'min prior/true', min(r[3]/r[4] for r in rows))
