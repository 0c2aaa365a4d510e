"""Deepest local-memory chain per entry: depot + aggregate .param/.retval bytes at each call."""
import re,subprocess,sys
lines=open(sys.argv[1]).read().splitlines()
want=sys.argv[2] if len(sys.argv)>2 else 'pt_chunk'
funcs={}; cur=None; blk=None
for line in lines:
    m=re.match(r'^(?:\.visible |\.weak |\.extern )*\.(entry|func)\s+(?:\([^)]*\)\s*)?([\w$]+)\(',line)
    if m: cur=m.group(2); funcs[cur]={'depot':0,'calls':[]}; continue
    if cur is None: continue
    m=re.search(r'\.local .*__local_depot\d+\[(\d+)\]',line)
    if m: funcs[cur]['depot']=int(m.group(1)); continue
    if '{ // callseq' in line: blk={'agg':0,'callee':None,'nxt':False}; continue
    if blk is not None:
        m=re.search(r'\.param .*\.b8 \w+\[(\d+)\]',line)
        if m: blk['agg']+=int(m.group(1))
        if re.match(r'\s*call',line):
            m=re.search(r'call(?:\.uni)?\s*(?:\([^)]*\),\s*)?(_Z[\w$]+)',line)
            if m: blk['callee']=m.group(1)
            else: blk['nxt']=True
            continue
        if blk['nxt']:
            blk['callee']=line.strip().rstrip(',').strip(); blk['nxt']=False
        if '} // callseq' in line:
            funcs[cur]['calls'].append((blk['callee'],blk['agg'])); blk=None
memo={}
def best(f,stack=()):
    if f in memo: return memo[f]
    if f not in funcs or f in stack: return (0,[])
    d=funcs[f]['depot']; b=(d,[(f,d,0)])
    for c,agg in funcs[f]['calls']:
        s,ch=best(c,stack+(f,))
        if d+agg+s>b[0]: b=(d+agg+s,[(f,d,agg)]+ch)
    memo[f]=b; return b
names=list(funcs)
dm=dict(zip(names,subprocess.run(['c++filt'],input='\n'.join(names),capture_output=True,text=True).stdout.splitlines()))
def sh(n):
    x=dm.get(n,n); return x.split('(')[0][-50:] if 'each_kernel' not in x else 'KERNEL'
for f in funcs:
    if want in dm[f] and 'each_kernel' in dm[f] and f.startswith('_ZN7lantern11cuda_detail11each_kernel'):
        tot,ch=best(f)
        if tot<200: continue
        print(tot, f[60:130]); print('   ', ' -> '.join(f'{sh(n)}[{d}+{a}]' for n,d,a in ch))
