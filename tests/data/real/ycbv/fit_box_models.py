# Fits the cuboid models of the gelatin box (class 8) and the foam brick (class 21) to the
# dataset's own vertmap (per-pixel model coordinates rendered from the YCB-Video models at the
# ground-truth poses): minimum-area rectangle in the model x-y plane (0.1 deg steps, 0.1/99.9 %
# quantiles), extents from the 0.05/99.95 % quantiles. Run from this folder (pure Python 3,
# about 2 min on an idle core); the box() calls below hold the numbers it printed.
import zlib, struct, sys, array
def png(p):
    b=open(p,'rb').read(); off=8; idat=b''; 
    while off<len(b):
        n,t=struct.unpack_from('>I4s',b,off); d=b[off+8:off+8+n]
        if t==b'IHDR': w,h,bd,ct=struct.unpack_from('>IIBB',d)
        if t==b'IDAT': idat+=d
        off+=12+n
    raw=zlib.decompress(idat); bpp={0:1,2:3,4:2,6:4}[ct]*(bd//8); stride=w*bpp
    out=bytearray(h*stride); prev=bytearray(stride)
    for y in range(h):
        f=raw[y*(stride+1)]; line=bytearray(raw[y*(stride+1)+1:(y+1)*(stride+1)])
        for i in range(stride):
            a=line[i-bpp] if i>=bpp else 0; up=prev[i]; c=prev[i-bpp] if i>=bpp else 0
            if f==1: line[i]=(line[i]+a)&255
            elif f==2: line[i]=(line[i]+up)&255
            elif f==3: line[i]=(line[i]+(a+up)//2)&255
            elif f==4:
                pa=abs(up-c); pb=abs(a-c); pc=abs(a+up-2*c)
                pr=a if pa<=pb and pa<=pc else (up if pb<=pc else c)
                line[i]=(line[i]+pr)&255
        out[y*stride:(y+1)*stride]=line; prev=line
    return w,h,bd,ct,out
def elems(buf,off,end):
    while off<end:
        t,n=struct.unpack_from('<II',buf,off)
        if t>>16: yield t&0xffff,buf[off+4:off+4+(t>>16)]; off+=8
        else: yield t,buf[off+8:off+8+n]; off+=8+(n if t==15 else ((n+7)//8)*8)
def mat(p):
    b=open(p,'rb').read(); out={}
    for t,d in elems(b,128,len(b)):
        if t==15: d=zlib.decompress(d); t,d=next(elems(d,0,len(d)))
        it=list(elems(d,0,len(d)))
        dims=struct.unpack('<%di'%(len(it[1][1])//4),it[1][1]); name=it[2][1].decode()
        if len(it)>3:
            tt,dd=it[3]; code={7:'f',9:'d'}.get(tt)
            if code: out[name]=(dims,array.array(code,dd))
    return out
allp={}
for k in range(1,11):
    fr='data/0000/%06d'%k
    w,h,bd,ct,lab=png(fr+'-label.png'); m=mat(fr+'-meta.mat'); dims,vm=m['vertmap']; N=480*640
    for v in range(0,480):
        for u in range(0,640):
            l=lab[v*640+u]
            if l in (8,21):
                i=v+480*u; allp.setdefault(l,[]).append((vm[i],vm[i+N],vm[i+2*N]))
def q(s,a): return s[int(a*(len(s)-1))]
for l,P in sorted(allp.items()):
    best=None
    for step in range(0,1800):
        a=math.radians(step/10); c,s=math.cos(a),math.sin(a)
        xs=sorted(c*p[0]+s*p[1] for p in P[::7]); ys=sorted(-s*p[0]+c*p[1] for p in P[::7])
        area=(q(xs,.999)-q(xs,.001))*(q(ys,.999)-q(ys,.001))
        if best is None or area<best[0]: best=(area,step/10)
    a=math.radians(best[1]); c,s=math.cos(a),math.sin(a)
    xs=sorted(c*p[0]+s*p[1] for p in P); ys=sorted(-s*p[0]+c*p[1] for p in P); zs=sorted(p[2] for p in P)
    print(l,len(P),'angle',best[1],'x',q(xs,.0005),q(xs,.9995),'y',q(ys,.0005),q(ys,.9995),'z',q(zs,.0005),q(zs,.9995))

def box(name, angle_deg, x0,x1,y0,y1,z0,z1, path):
    a=math.radians(angle_deg); c,s=math.cos(a),math.sin(a)
    V=[]
    for z in (z0,z1):
        for (x,y) in ((x0,y0),(x1,y0),(x1,y1),(x0,y1)):
            # fitted frame (x', y') = R(-a) (x, y): back to model coordinates with R(a)
            V.append((c*x-s*y, s*x+c*y, z))
    F=[(1,3,2),(1,4,3),(5,6,7),(5,7,8),(1,2,6),(1,6,5),(2,3,7),(2,7,6),(3,4,8),(3,8,7),(4,1,5),(4,5,8)]
    with open(path,'w') as f:
        f.write('# %s: a cuboid fitted to the YCB-Video vertmap of video 0000 frames 1-10 (metres)\n'%name)
        f.write('# yaw %.1f deg, extents %.1f x %.1f x %.1f mm\n'%(angle_deg,(x1-x0)*1e3,(y1-y0)*1e3,(z1-z0)*1e3))
        for v in V: f.write('v %.6f %.6f %.6f\n'%v)
        for t in F: f.write('f %d %d %d\n'%t)
box('009_gelatin_box',13.4,-0.037488,0.033736,-0.043788,0.043377,-0.018596,0.008330,'009_gelatin_box.obj')
box('061_foam_brick',89.1,-0.036940,0.038496,-0.025746,0.025068,-0.017212,0.032983,'061_foam_brick.obj')
