#!/usr/bin/env python3
"""Public items under clearance_joint::rapier in a rustdoc JSON file (see .ci/public-items)."""
import json,sys,collections
d=json.load(open(sys.argv[1]))
idx=d['index']; root=idx[str(d['root'])]
def inner(it): 
    k=list(it['inner'].keys())[0]; return k,it['inner'][k]
seen=set(); counts=collections.Counter(); per=collections.Counter()
def visit(i,path,count):
    i=str(i)
    if i in seen or i not in idx: return
    seen.add(i); it=idx[i]; k,v=inner(it)
    if it.get('crate_id',0)!=0: return
    name=it.get('name')
    p=path+[name] if name else path
    if count and k not in ('impl',):
        counts[k]+=1; per['::'.join(p[:4])]+=1
    if k=='module':
        for c in v['items']: visit(c,p,count)
    elif k in('struct','union'):
        kind=v.get('kind',{})
        if isinstance(kind,dict) and 'plain' in kind:
            for f in kind['plain']['fields']: visit(f,p,count)
        elif isinstance(kind,dict) and 'tuple' in kind:
            for f in kind['tuple']: 
                if f is not None: visit(f,p,count)
        for im in v['impls']: visit(im,p,count)
    elif k=='enum':
        for x in v['variants']: visit(x,p,count)
        for im in v['impls']: visit(im,p,count)
    elif k=='impl':
        if v.get('trait') is None and not v.get('is_synthetic') and not v.get('blanket_impl'):
            for c in v['items']: visit(c,path,count)
    elif k=='trait':
        for c in v['items']: visit(c,p,count)
    elif k=='use':
        tgt=v.get('id')
        if tgt is not None: visit(tgt,path,count)
# find rapier module
for c in inner(root)[1]['items']:
    it=idx[str(c)]
    if it['name']==(sys.argv[2] if len(sys.argv)>2 else 'rapier'): visit(c,['rapier'],True)
print(sum(counts.values()), dict(counts))
for k,v in sorted(per.items(),key=lambda x:-x[1])[:40]: print(v,k)
