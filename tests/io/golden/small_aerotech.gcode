; rotomorph G-code (rotational multimaterial printing)
; tool: rotomorph 0.1.0
; design-sha256: 954abf4bacbdf3926504d0ad0b1acd518d70c069f1513a299f2d8958b17f0417
; machine: golden
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
G0 Z2.3000
G0 X10.0000 Y10.0000 A0.0000
G0 Z0.3000
Call setAlicatPress P5 Q30.000
Call setAlicatPress P6 Q20.000
G1 X10.5000 Y10.0000 A95.4930 F3.0000
G1 X11.0000 Y10.0000 A190.9859 F3.0000
G1 X11.5000 Y10.0000 A286.4789 F3.0000
G1 X12.0000 Y10.0000 A381.9719 F3.0000
Call setAlicatPress P5 Q0.000
Call setAlicatPress P6 Q0.000
; end filament 0
; filament 1 layer=0 radius=0.3 active_fraction=0.5 active_material=lce passive_material=acrylate
G0 Z2.3000
G0 X10.0000 Y12.0000 A28.6479
G0 Z0.3000
Call setAlicatPress P5 Q25.000
Call setAlicatPress P6 Q25.000
G1 X10.5000 Y12.0000 A28.6479 F1.5000
G1 X11.0000 Y12.0000 A28.6479 F1.5000
G1 X11.5000 Y12.0000 A28.6479 F1.5000
G1 X12.0000 Y12.0000 A28.6479 F1.5000
Call setAlicatPress P5 Q0.000
Call setAlicatPress P6 Q0.000
; end filament 1
; UV cure after layer 0: 600 s
G4 P600.000
; layer 1
; filament 2 layer=1 radius=0.3 active_fraction=1.0 active_material=lce passive_material=acrylate
G0 Z2.9000
G0 X10.0000 Y10.0000 A0.0000
G0 Z0.9000
Call setAlicatPress P5 Q40.000
Call setAlicatPress P6 Q0.000
G1 X10.5000 Y10.0000 A-95.4930 F2.0000
G1 X11.0000 Y10.0000 A-190.9859 F2.0000
G1 X11.5000 Y10.0000 A-286.4789 F2.0000
G1 X12.0000 Y10.0000 A-381.9719 F2.0000
Call setAlicatPress P5 Q0.000
Call setAlicatPress P6 Q0.000
; end filament 2
; UV cure after layer 1: 600 s
G4 P600.000
G0 Z2.9000
M2
