"""The README's hash-grid table from the JSON beside this script."""
import json, os, sys
D = os.path.dirname(os.path.abspath(__file__))
def load(name):
    p = os.path.join(D, name)
    return json.load(open(p)) if os.path.exists(p) and os.path.getsize(p) > 0 else None
def stage(t, name):
    return sum(s['wall_seconds'] for s in t['stages'] if s['name'] == name)
rows = []
cases = ['glass_ball_scene_grid', 'glass_ball_fine', 'cornell_own', 'cornell_own_r002', 'cornell_1024', 'cornell_obj_256']
print('| case | grid | storage | grid texels | build map (s) | radiance estimate (s) | RMSE vs SPPM | relative MSE |')
print('|---|---|---|---|---|---|---|---|')
for c in cases:
    for g in ['uniform', 'hash']:
        ph = load(f'{c}.{g}.photons.json'); r = load(f'{c}.{g}.render.json'); cmp = load(f'{c}.{g}.compare.json')
        if ph is None and r is None:
            err = os.path.join(D, f'{c}.{g}.photons.err')
            if os.path.exists(err) and os.path.getsize(err) > 0:
                print(f'| {c} | | {g} | refused: `{open(err).read().strip()[:90]}...` | | | | |')
            continue
        res = 'x'.join(map(str, ph['grid_resolution'])) if ph else ''
        st = ph['grid_storage'] if ph else ''
        st = 'uniform' if st == 'uniform' else f"hash, {st['hashed']['buckets']} buckets" if st else ''
        tex = ph['grid_texels'] if ph else ''
        build = f"{stage(r['timings'], 'build map'):.3f}" if r else ''
        est = f"{stage(r['timings'], 'radiance estimate'):.2f}" if r else ''
        rmse = f"{cmp['rmse']:.5f}" if cmp and 'rmse' in cmp else ''
        rel = f"{cmp['rel_mse']:.5f}" if cmp and 'rel_mse' in cmp else ''
        print(f'| {c} | {res} | {st} | {tex} | {build} | {est} | {rmse} | {rel} |')
