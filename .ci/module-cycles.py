#!/usr/bin/env python3
"""Module cycles in each crate (ARCHITECTURE.md: none). Usage: module-cycles.py [WORKSPACE].
Reports: a module that uses another which (directly or through others)
uses it back. Modules are files; an edge a -> b when a's code names crate::b (or super:: resolving
to b) other than a's own descendants/ancestors."""
import os,re,sys
root=sys.argv[1] if len(sys.argv)>1 else '.'
crates=[d for d in os.listdir(root) if os.path.isfile(os.path.join(root,d,'Cargo.toml')) and os.path.isdir(os.path.join(root,d,'src'))]
crates.append('.')
total=0
for c in sorted(crates):
    src=os.path.join(root,c,'src')
    mods={}
    for dp,_,fs in os.walk(src):
        for f in fs:
            if not f.endswith('.rs'): continue
            p=os.path.join(dp,f); rel=os.path.relpath(p,src)[:-3]
            parts=rel.split(os.sep)
            if parts[-1] in ('mod','lib','main'): parts=parts[:-1]
            mods[tuple(parts)]=open(p).read()
    def resolve(path):
        # longest module prefix
        for k in range(len(path),0,-1):
            if tuple(path[:k]) in mods: return tuple(path[:k])
        return None
    edges={m:set() for m in mods}
    for m,text in mods.items():
        # strip test modules
        text=re.split(r'#\[cfg\(test\)\]\s*mod tests',text)[0]
        # Comments (doc links included) are not dependencies.
        text=re.sub(r'//[^\n]*','',text)
        for mt in re.finditer(r'\b(crate|super(?:::super)*)((?:::\w+)+)',text):
            head,rest=mt.group(1),mt.group(2).split('::')[1:]
            if head=='crate': base=[]
            else:
                n=head.count('super')
                # a file module's super is its parent
                base=list(m[:-n]) if len(m)>=n else []
            # expand braces roughly: only first segment matters
            t=resolve(base+rest)
            if t is None or t==m: continue
            # ignore ancestor/descendant
            if t==m[:len(t)] or m==t[:len(m)]: continue
            edges[m].add(t)
    # collapse to sibling-level: edge between children of common parent
    # Tarjan SCC on full graph
    idx={};low={};st=[];on=set();sccs=[];i=[0]
    sys.setrecursionlimit(10000)
    def sc(v):
        idx[v]=low[v]=i[0];i[0]+=1;st.append(v);on.add(v)
        for w in edges[v]:
            if w not in idx: sc(w);low[v]=min(low[v],low[w])
            elif w in on: low[v]=min(low[v],idx[w])
        if low[v]==idx[v]:
            comp=[]
            while True:
                w=st.pop();on.discard(w);comp.append(w)
                if w==v:break
            if len(comp)>1: sccs.append(comp)
    for v in edges:
        if v not in idx: sc(v)
    for comp in sccs:
        total+=1
        print(f"{c}: cycle among "+", ".join('::'.join(x) or 'lib' for x in sorted(comp)))
print(f"{total} module cycle(s)")
sys.exit(1 if total else 0)
