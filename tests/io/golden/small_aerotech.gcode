; rotomorph G-code (rotational multimaterial printing)
; tool: rotomorph 0.1.0
; design-sha256: 954abf4bacbdf3926504d0ad0b1acd518d70c069f1513a299f2d8958b17f0417
; machine: golden, built-in default (no machine profile given: its envelope and limits are assumptions; pass --machine FILE for your printer)
; limits: envelope [0.0, 0.0, 0.0]..[300.0, 300.0, 100.0] mm, feed 0.01..50 mm/s, rotation <= 40 rad/s (travel included), pressure 0..100 psi, lift 2 mm
; dialect: aerotech, pressure idiom alicat
; units: length mm, feed mm/s, rotary deg, pressure psi, dwell s
; axes: X=x Y=y Z=z (design z + z_offset 0 mm; Z 0 = substrate surface in the active work offset)
; rotary: C = nozzle angle of the active half, counter-clockwise from +x seen from above times sign +1; must read 0 with the active half toward +x at the start; cumulative within a filament, re-based with G92 between filaments (restored at the end), |C| <= 360 deg
; pressure channels: active port 5, passive port 6
; filaments: 3, layers: 2, order: serpentine
; estimated print time: 124.6 s
G71
G76
G90
; layer 0
; filament 0 layer=0 radius=0.3 active_fraction=0.5 active_material=lce passive_material=acrylate
G0 Z2.3
G0 X10 Y10
G1 F20
G1 Z0.3 C0
Call setAlicatPress P5 Q30
Call setAlicatPress P6 Q20
G4 P0.5
G1 F3
G1 X10.5 Y10 C95.492966
G1 X11 Y10 C190.985932
G1 X11.5 Y10 C286.478898
G1 X12 Y10 C381.971863
Call setAlicatPress P5 Q0
Call setAlicatPress P6 Q0
G4 P0.25
; end filament 0
; filament 1 layer=0 radius=0.3 active_fraction=0.5 active_material=lce passive_material=acrylate
G0 Z2.3
G0 X12 Y12
G92 C21.971863
G1 F20
G1 Z0.3 C151.35211
Call setAlicatPress P5 Q25
Call setAlicatPress P6 Q25
G1 F1.5
G1 X11.5 Y12 C151.35211
G1 X11 Y12 C151.35211
G1 X10.5 Y12 C151.35211
G1 X10 Y12 C151.35211
Call setAlicatPress P5 Q0
Call setAlicatPress P6 Q0
; end filament 1
G0 Z2.9
; UV cure after layer 0: 60 s (no UV command in the machine profile: switch the lamp by hand)
G4 P60
; layer 1
; filament 2 layer=1 radius=0.3 active_fraction=1.0 active_material=lce passive_material=acrylate
G0 X10 Y10
G1 F20
G1 Z0.9 C0
Call setAlicatPress P5 Q40
G1 F2
G1 X10.5 Y10 C-95.492966
G1 X11 Y10 C-190.985932
G1 X11.5 Y10 C-286.478898
G1 X12 Y10 C-381.971863
Call setAlicatPress P5 Q0
; end filament 2
G0 Z2.9
; UV cure after layer 1: 60 s (no UV command in the machine profile: switch the lamp by hand)
G4 P60
G92 C-21.971863
M2
