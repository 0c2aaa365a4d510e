"""2026-12-02-stack2/chains.py's model (deepest chain of PTX local depots plus call
parameters) with some functions' depots lowered, to see which chain is next deepest:
    python chains_whatif.py PTX KERNEL_SUBSTRING "mix_eval:376,bdpt_camera_connect:320" [MIN]
(name: zero; name:N: N bytes less). Only a guide: ptxas's frames came out 236-503 B above it."""
import os,re,subprocess,sys
exec(open(os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', '2026-12-02-stack2',
                       'chains.py')).read().split('memo={}')[0])
zero=sys.argv[3].split(',') if len(sys.argv)>3 else []
names=list(funcs)
dm=dict(zip(names,subprocess.run(['c++filt'],input='\n'.join(names),capture_output=True,text=True).stdout.splitlines()))
for f in funcs:
    for z in zero:
        if not z: continue
        name,_,sub=z.partition(':')
        if name in dm[f].split('(')[0]: funcs[f]['depot']=max(0,funcs[f]['depot']-int(sub)) if sub else 0
memo={}
def best(f,stack=()):
    if f in memo: return memo[f]
    if f not in funcs or f in stack: return (0,[])
    d=funcs[f]['depot']; b=(d,[(f,d,0)])
    for c,agg in funcs[f]['calls']:
        s,ch=best(c,stack+(f,))
        if d+agg+s>b[0]: b=(d+agg+s,[(f,d,agg)]+ch)
    memo[f]=b; return b
def sh(n):
    x=dm.get(n,n); return x.split('(')[0][-50:] if 'each_kernel' not in x else 'KERNEL'
for f in funcs:
    if want in dm[f] and 'each_kernel' in dm[f] and f.startswith('_ZN7lantern11cuda_detail11each_kernel'):
        tot,ch=best(f)
        if tot<int(sys.argv[4] if len(sys.argv)>4 else 1000): continue
        print(tot); print('   ', ' -> '.join(f'{sh(n)}[{d}+{a}]' for n,d,a in ch))
