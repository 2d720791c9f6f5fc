<?xml version="1.0" encoding="UTF-8"?>
<core:CityModel xmlns:core="http://www.opengis.net/citygml/2.0" xmlns:bldg="http://www.opengis.net/citygml/building/2.0" xmlns:gml="http://www.opengis.net/gml" xmlns:xlink="http://www.w3.org/1999/xlink">
<gml:boundedBy><gml:Envelope srsName="EPSG:25832" srsDimension="3"><gml:lowerCorner>400000 5860000 40</gml:lowerCorner><gml:upperCorner>400100 5860100 48</gml:upperCorner></gml:Envelope></gml:boundedBy>
<core:cityObjectMember><bldg:Building gml:id="NO_GEOMETRY"><bldg:measuredHeight uom="m">8</bldg:measuredHeight></bldg:Building></core:cityObjectMember>
</core:CityModel>
