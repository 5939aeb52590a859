; rotomorph G-code (rotational multimaterial printing)
; tool: rotomorph 0.1.0
; design-sha256: 954abf4bacbdf3926504d0ad0b1acd518d70c069f1513a299f2d8958b17f0417
; machine: golden, built-in default (no machine profile given: its envelope and limits are assumptions; pass --machine FILE for your printer)
; limits: envelope [0.0, 0.0, 0.0]..[300.0, 300.0, 100.0] mm, feed 0.01..50 mm/s, rotation <= 40 rad/s, pressure 0..100 psi, travel lift 2 mm
; dialect: aerotech
; units: length mm, feed mm/s, rotary deg, pressure psi
; axes: X=x Y=y Z=z A=nozzle angle (sign +1, ccw from +x seen from above), cumulative
; pressure channels: active port 5, passive port 6
; filaments: 3, layers: 2
; estimated print time: 1203.7 s
G71
G76
G90
; layer 0
; filament 0 layer=0 radius=0.3 active_fraction=0.5 active_material=lce passive_material=acrylate
G0 Z2.3
G0 X10 Y10 A0
G0 Z0.3
Call setAlicatPress P5 Q30
Call setAlicatPress P6 Q20
G1 X10.5 Y10 A95.492966 F3
G1 X11 Y10 A190.985932 F3
G1 X11.5 Y10 A286.478898 F3
G1 X12 Y10 A381.971863 F3
Call setAlicatPress P5 Q0
Call setAlicatPress P6 Q0
; end filament 0
; filament 1 layer=0 radius=0.3 active_fraction=0.5 active_material=lce passive_material=acrylate
G0 Z2.3
G0 X10 Y12 A28.64789
G0 Z0.3
Call setAlicatPress P5 Q25
Call setAlicatPress P6 Q25
G1 X10.5 Y12 A28.64789 F1.5
G1 X11 Y12 A28.64789 F1.5
G1 X11.5 Y12 A28.64789 F1.5
G1 X12 Y12 A28.64789 F1.5
Call setAlicatPress P5 Q0
Call setAlicatPress P6 Q0
; end filament 1
; UV cure after layer 0: 600 s
G4 P600
; layer 1
; filament 2 layer=1 radius=0.3 active_fraction=1.0 active_material=lce passive_material=acrylate
G0 Z2.9
G0 X10 Y10 A0
G0 Z0.9
Call setAlicatPress P5 Q40
Call setAlicatPress P6 Q0
G1 X10.5 Y10 A-95.492966 F2
G1 X11 Y10 A-190.985932 F2
G1 X11.5 Y10 A-286.478898 F2
G1 X12 Y10 A-381.971863 F2
Call setAlicatPress P5 Q0
Call setAlicatPress P6 Q0
; end filament 2
; UV cure after layer 1: 600 s
G4 P600
G0 Z2.9
M2
